// Test-only: the map serving a fixed plan while a vehicle drives along it, for the browser test
// (tests/integration/ground_map). Prints "listening on http://127.0.0.1:PORT/" once it serves.
//
//   airseg-map-fixture [--control] [--seconds N] [--fixless-first K] [--lose-fix-after K] [--outage-after K]
//                      [--hold-after K] [--moment start|mid-scan|outage] [--web-dir DIR] [--leaflet-dir DIR]
// N (default 60): how long the vehicle drives and the event stream stays open, from the first browser
// connection. --fixless-first K: the first K samples have no position (sent as 0,0, as the daemon does before
// a GPS fix); --lose-fix-after K: every sample after the first K has none; --outage-after K: after K samples
// the link goes down and no sample comes any more; --hold-after K: after K samples the vehicle sends its K-th
// sample again and again (the picture stays at that moment, fresh, however late the browser comes).
//
// --moment puts the survey at one moment of the pictures in docs/images (4 samples a leg):
//   start     holds after 3 samples: leaving the start, heading for waypoint 2 of 14;
//   mid-scan  holds after 18 samples: on the scan's second line, heading for waypoint 6 of 14;
//   outage    the link goes down after 26 samples: on the scan's third line, heading for waypoint 8 of 14.
//
// The plan has 14 waypoints (plan.show's counts are in "waypoints" and "top", as the hub adds them); each
// waypoint reached sends what an older vehicle sends (the board's "Reached waypoint #N", the window's slot, a
// "Flight plan received") and the plan's own event, twice, plus a mode change that changes nothing.
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "ground/map/map_server.hpp"

using airseg::ground::MapConfig;
using airseg::ground::MapServer;
using Json = nlohmann::json;

namespace {

Json fixture_plan() {
    return Json::parse(R"({
      "name": "fixture <survey> & co",
      "generation": 1,
      "truncated": false,
      "elements": [
        {"path": "plan.elements[0]", "kind": "waypoint", "name": "start", "closed": false,
         "points": [[41.2752, 1.9868]]},
        {"path": "plan.elements[1]", "kind": "waypoint", "name": null, "closed": false,
         "points": [[41.2757, 1.9868]]},
        {"path": "plan.elements[2]", "kind": "scan", "name": "field", "closed": true,
         "points": [[41.2757, 1.9870], [41.2763, 1.9870], [41.2763, 1.9882], [41.2757, 1.9882]],
         "lines": [[41.2757, 1.9871], [41.2763, 1.9871], [41.2763, 1.9878], [41.2757, 1.9878],
                   [41.2757, 1.9881], [41.2763, 1.9881]]},
        {"path": "plan.elements[3]", "kind": "hold", "name": "wait", "closed": false, "hold_s": 20,
         "points": [[41.2760, 1.9875]]},
        {"path": "plan.elements[4]", "kind": "orbit", "name": null, "closed": false,
         "points": [[41.2761, 1.9887], [41.2760, 1.9888], [41.2759, 1.9887], [41.2760, 1.9886], [41.2761, 1.9887]]}
      ],
      "waypoints": 14,
      "top": [{"path": "plan.elements[0]", "kind": "waypoint", "name": "start", "waypoints": 1},
              {"path": "plan.elements[1]", "kind": "waypoint", "name": "", "waypoints": 1},
              {"path": "plan.elements[2]", "kind": "scan", "name": "field", "waypoints": 6},
              {"path": "plan.elements[3]", "kind": "hold", "name": "wait", "waypoints": 1},
              {"path": "plan.elements[4]", "kind": "orbit", "name": "", "waypoints": 5}],
      "no_fly": [{"name": "pond", "points": [[41.2770, 1.9890], [41.2770, 1.9896], [41.2766, 1.9896], [41.2766, 1.9890]]}]
    })");
}

struct RoutePoint {
    double lat = 0;
    double lon = 0;
    std::uint16_t element = 0;  // the top-level element it belongs to
};

/// The route the simulated vehicle drives: every point of the plan in order, round and round.
std::vector<RoutePoint> route_of(const Json& plan) {
    std::vector<RoutePoint> route;
    std::uint16_t element = 0;
    for (const auto& e : plan["elements"]) {
        const auto& pts = e.contains("lines") ? e["lines"] : e["points"];
        for (const auto& p : pts) {
            route.push_back({p[0].get<double>(), p[1].get<double>(), element});
        }
        ++element;
    }
    return route;
}

}  // namespace

int main(int argc, char** argv) {
    MapConfig config;
    config.listen = "127.0.0.1:0";
    double seconds = 60;
    long fixless_first = 0;
    long lose_fix_after = -1;
    long outage_after = -1;
    long hold_after = -1;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        const bool has_value = i + 1 < argc;
        if (arg == "--control") {
            config.control = true;
        } else if (arg == "--seconds" && has_value) {
            seconds = std::stod(argv[++i]);
        } else if (arg == "--fixless-first" && has_value) {
            fixless_first = std::stol(argv[++i]);
        } else if (arg == "--lose-fix-after" && has_value) {
            lose_fix_after = std::stol(argv[++i]);
        } else if (arg == "--outage-after" && has_value) {
            outage_after = std::stol(argv[++i]);
        } else if (arg == "--hold-after" && has_value) {
            hold_after = std::stol(argv[++i]);
        } else if (arg == "--moment" && has_value) {
            const std::string moment = argv[++i];
            if (moment == "start") {
                hold_after = 3;
            } else if (moment == "mid-scan") {
                hold_after = 18;
            } else if (moment == "outage") {
                outage_after = 26;
            } else {
                std::fprintf(stderr, "airseg-map-fixture: unknown moment %s (start, mid-scan, outage)\n",
                             moment.c_str());
                return 2;
            }
        } else if (arg == "--web-dir" && has_value) {
            config.web_dir = argv[++i];
        } else if (arg == "--leaflet-dir" && has_value) {
            config.leaflet_dir = argv[++i];
        } else if (arg == "--listen" && has_value) {
            config.listen = argv[++i];
        } else {
            std::fprintf(stderr, "airseg-map-fixture: unknown argument %s\n", arg.c_str());
            return 2;
        }
    }

    airseg::asio::io_context io;
    auto strand = airseg::asio::make_strand(io);
    MapServer* map_ptr = nullptr;
    MapServer map(strand, config, [&map_ptr](Json request, std::function<void(Json)> done) {
        map_ptr->add_event("command " + request.value("cmd", std::string()));
        std::printf("vehicle got the command %s\n", request.dump().c_str());
        std::fflush(stdout);
        done({{"ok", true}, {"result", {{"state", "running"}}}});
    });
    map_ptr = &map;
    if (const auto error = map.start(); !error.empty()) {
        std::fprintf(stderr, "airseg-map-fixture: %s\n", error.c_str());
        return 1;
    }
    const Json plan = fixture_plan();
    map.set_plan(plan);
    map.set_link({{"link", "up"}, {"rtt_ms", 84}, {"loss", 0.02}, {"goodput_bps", 2400}});
    map.add_event("plan fixture <survey> loaded & running");
    std::printf("listening on http://127.0.0.1:%u/\n", static_cast<unsigned>(map.port()));
    std::fflush(stdout);

    const auto route = route_of(plan);
    std::size_t leg = 0;
    double along = 0.0;
    airseg::asio::steady_timer step(strand);
    airseg::asio::steady_timer end(strand);
    airseg::asio::signal_set signals(io, SIGINT, SIGTERM);
    bool end_armed = false;
    long samples = 0;
    airseg::groundlink::protocol::Telemetry held;  // the last sample sent, sent again while holding
    std::function<void()> drive;
    const auto drive_again = [&] {  // the next sample in 100 ms
        step.expires_after(std::chrono::milliseconds(100));
        step.async_wait([&](boost::system::error_code ec) {
            if (!ec) {
                drive();
            }
        });
    };
    drive = [&] {
        if (!end_armed && map.connections_accepted() > 0) {
            // The run is counted from the browser's first request: a browser slow to start (a loaded
            // machine) finds the page served all the same.
            end_armed = true;
            end.expires_after(std::chrono::milliseconds(static_cast<long>(seconds * 1000)));
            end.async_wait([&](boost::system::error_code ec) {
                if (!ec) {
                    step.cancel();
                    map.stop();
                    signals.cancel();
                }
            });
        }
        const auto [lat0, lon0, element0] = route[leg % route.size()];
        const auto [lat1, lon1, element1] = route[(leg + 1) % route.size()];
        (void)element0;
        airseg::groundlink::protocol::Telemetry t;
        t.next_waypoint = static_cast<std::uint32_t>((leg + 1) % route.size());
        t.plan_element = element1;
        t.lat_deg = lat0 + (lat1 - lat0) * along;
        t.lon_deg = lon0 + (lon1 - lon0) * along;
        t.alt_m = 10;
        t.ground_speed_mps = 1.5;
        t.heading_deg = std::fmod(
            std::atan2((lon1 - lon0) * std::cos(lat0 * M_PI / 180.0), lat1 - lat0) * 180.0 / M_PI + 360.0,
            360.0);
        t.battery_v = 12.4;
        t.battery_pct = 80;
        t.plan_state = 1;
        t.gps_fix = 3;
        const long n = samples++;
        if (hold_after > 0 && n >= hold_after) {
            map.add_position(held, std::chrono::system_clock::now());
            drive_again();
            return;
        }
        if (outage_after >= 0 && n >= outage_after) {
            if (n == outage_after) {
                map.set_link({{"link", "down"}, {"rtt_ms", 84}, {"loss", 0.0}});
            }
            drive_again();
            return;
        }
        if (n < fixless_first || (lose_fix_after >= 0 && n >= lose_fix_after)) {
            t.no_position = true;
            t.lat_deg = 0;
            t.lon_deg = 0;
            t.gps_fix = 1;
        }
        map.add_position(t, std::chrono::system_clock::now());
        held = t;
        along += 0.25;
        if (along >= 1.0) {
            along = 0.0;
            ++leg;
            // The waypoint just reached, as an older vehicle tells it and as the plan does.
            using airseg::groundlink::protocol::Event;
            const auto reached = leg % route.size();
            const auto slot = 2 + leg % 6;
            for (const std::string& text :
                 {"autopilot: Reached waypoint #" + std::to_string(slot) + " dist 1m",
                  "mission slot " + std::to_string(slot) + " reached",
                  std::string("autopilot: Flight plan received"),
                  "plan waypoint " + std::to_string(reached) + " reached",
                  "plan waypoint " + std::to_string(reached) + " reached",
                  std::string("autopilot mode AUTO -> AUTO")}) {
                map.add_event(Event{Event::Severity::Info, text});
            }
        }
        drive_again();
    };
    airseg::asio::post(strand, drive);
    signals.async_wait([&](boost::system::error_code, int) {
        airseg::asio::post(strand, [&] {
            end.cancel();
            step.cancel();
            map.stop();
        });
    });
    io.run();
    return 0;
}
