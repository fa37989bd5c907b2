#include "client/live_commands.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <csignal>
#include <iostream>
#include <thread>

#include "client/json_text.hpp"
#include "client/stick_input.hpp"
#include "groundside/event_wording.hpp"
#include "groundside/watch_view.hpp"

namespace airseg::client {

namespace proto = groundlink::protocol;
using Clock = std::chrono::steady_clock;

namespace {

volatile std::sig_atomic_t g_stop = 0;

constexpr int kDone = 0;
constexpr int kRefused = 1;
constexpr int kNoLink = 3;
constexpr int kRoutePoints = 300;

bool expired(const LiveOptions& o, Clock::time_point started) {
    return o.duration.count() > 0 && Clock::now() - started >= o.duration;
}

/// Waits until the link is up (the vehicle pushes nothing before); false after the timeout.
bool wait_for_link(VehicleLink& radio, const LiveOptions& o,
                   const std::function<void(const proto::Message&)>& on_message) {
    const auto deadline = Clock::now() + o.timeout;
    while (!radio.link_up() && g_stop == 0) {
        if (Clock::now() >= deadline) {
            std::cerr << "airsegctl: no link to the vehicle within " << o.timeout.count() << " ms\n";
            return false;
        }
        radio.run_for(std::chrono::milliseconds(50), on_message);
    }
    return true;
}

bool drives(std::uint8_t plan_state) {
    return plan_state == 1 || plan_state == 2;  // running, paused
}

/// What the vehicle says of its plan (plan.show; with `route`, plan.geometry for the distance left): the
/// plan's count and element names, so progress and events read "waypoint 4 of 12" as on the map. What the
/// vehicle pushes while it asks goes to `on_message`, as the live views see it.
groundside::PlanFacts ask_plan(VehicleLink& radio, const LiveOptions& o, bool route,
                               const VehicleLink::MessageHandler& on_message) {
    const auto show = radio.request({{"cmd", "plan.show"}}, o.timeout, on_message);
    if (!show.answer || !show.answer->value("ok", false)) {
        return {};
    }
    nlohmann::json geometry;
    if (route) {
        // Few points: the answer crosses the radio; a longer plan is drawn in part and has no distance left.
        auto shape =
            radio.request({{"cmd", "plan.geometry"}, {"max_points", kRoutePoints}}, o.timeout, on_message);
        if (shape.answer && shape.answer->value("ok", false)) {
            geometry = std::move((*shape.answer)["result"]);
        }
    }
    return groundside::plan_facts((*show.answer)["result"], geometry);
}

/// A message after which the plan's facts are to be asked again: a plan started to drive (`last_state`, the
/// plan state seen before, none at first), or the vehicle announced another plan over the one that drove.
bool tells_of_a_new_plan(const proto::Message& m, std::optional<std::uint8_t>& last_state) {
    if (const auto* t = std::get_if<proto::Telemetry>(&m)) {
        const bool started = drives(t->plan_state) && !(last_state && drives(*last_state));
        last_state = t->plan_state;
        return started;
    }
    const auto* e = std::get_if<proto::Event>(&m);
    return e != nullptr && groundside::announces_plan(e->text);
}

}  // namespace

std::string notes_text(const LiveOptions& o) {
    std::string out;
    for (const auto& note : o.notes) {
        out += "\n" + note;
    }
    return out.empty() ? out : out + "\n";
}

void install_stop_handlers() {
    std::signal(SIGINT, [](int) { g_stop = 1; });
    std::signal(SIGTERM, [](int) { g_stop = 1; });
}

bool stop_requested() {
    return g_stop != 0;
}

int run_radio_watch(VehicleLink& radio, const LiveOptions& o) {
    groundside::WatchState state;
    state.set_debug(o.debug);
    // The plan's facts are asked again whenever a plan starts to drive (a new one, or the first seen) or
    // another takes over; the view keeps taking what the vehicle pushes while it asks.
    std::optional<std::uint8_t> plan_state;
    bool ask = false;
    auto take = [&](const proto::Message& m) {
        state.take(m, Clock::now());
        if (tells_of_a_new_plan(m, plan_state)) {
            state.set_plan({});  // the last plan's facts are not this one's
            ask = true;
        }
    };
    if (!wait_for_link(radio, o, take)) {
        return kNoLink;
    }
    const bool tty = ::isatty(STDOUT_FILENO) == 1;
    const auto started = Clock::now();
    if (tty && !o.json) {
        std::cout
            << "\x1b[?25l\x1b[2J";  // hide the cursor, clear once; each refresh then overwrites in place
    }
    while (g_stop == 0 && !expired(o, started)) {
        const auto next = Clock::now() + o.refresh;
        radio.run_for(o.refresh, take);
        while (ask && g_stop == 0) {
            ask = false;  // set again if another plan is announced while this one is asked for
            auto facts = ask_plan(radio, o, true, take);
            if (!ask) {
                state.set_plan(std::move(facts));
            }
        }
        // The view is redrawn at its interval only, even over a link that returns early (nothing to wait on).
        std::this_thread::sleep_until(next);
        state.set_ground_link(radio.link_stats());
        const auto now = Clock::now();
        if (o.json) {
            std::cout << dump_text(state.to_json(now)) << "\n" << std::flush;
        } else if (tty) {
            // Home, then each line cleared to its end, then the rest of the screen: no flicker.
            std::string screen = state.render(now) + notes_text(o);
            std::string framed = "\x1b[H";
            for (std::size_t start = 0; start < screen.size();) {
                const auto nl = screen.find('\n', start);
                framed += screen.substr(start, nl - start) + "\x1b[K\n";
                start = nl == std::string::npos ? screen.size() : nl + 1;
            }
            std::cout << framed << "\x1b[J" << std::flush;
        } else {
            std::cout << state.render(now) << notes_text(o) << "\n" << std::flush;
        }
    }
    if (tty && !o.json) {
        std::cout << "\x1b[?25h" << std::flush;
    }
    return kDone;
}

int run_log(VehicleLink& radio, const LiveOptions& o) {
    // Worded as watch and the map word them: in plan terms, each happening once.
    groundside::EventWording wording;
    std::optional<std::uint8_t> plan_state;  // none before the first sample
    bool ask = true;                         // the running plan's count: "waypoint 8 of 12 reached"
    auto print = [&o, &wording, &plan_state, &ask](const proto::Message& m) {
        if (tells_of_a_new_plan(m, plan_state)) {
            // No count is better than a wrong one until the new plan's is known.
            wording.set_waypoints(std::nullopt);
            ask = true;
        }
        const auto e = wording.take(m, Clock::now());
        if (!e || (e->debug && !o.debug)) {
            return;
        }
        if (o.json) {
            nlohmann::json j{{"severity", groundside::event_severity_name(e->severity)}, {"text", e->text}};
            if (o.debug) {
                j["raw"] = e->raw;
                j["debug"] = e->debug;
            }
            std::cout << dump_text(j) << "\n" << std::flush;
        } else {
            std::cout << groundside::event_line(*e, o.debug) << "\n" << std::flush;
        }
    };
    if (!wait_for_link(radio, o, print)) {
        return kNoLink;
    }
    const auto started = Clock::now();
    while (g_stop == 0 && !expired(o, started)) {
        // Asked while the events go on printing (they are numbered without "of N" until it is known).
        while (ask && g_stop == 0) {
            ask = false;
            const auto plan = ask_plan(radio, o, false, print);
            if (!ask && plan.waypoints) {
                wording.set_waypoints(plan.waypoints);
            }
        }
        radio.run_for(std::chrono::milliseconds(100), print);
    }
    return kDone;
}

int run_joystick(VehicleLink& radio, const LiveOptions& o, const JoystickOptions& j) {
    std::string error;
    // The first input is a command: the vehicle acknowledges that this station may drive (a monitor key is
    // refused here, before any stick input is streamed).
    auto first = radio.request({{"cmd", "joystick"}, {"steering", 0.0}, {"throttle", 0.0}}, o.timeout, {});
    if (!first.answer) {
        std::cerr << "airsegctl: " << first.error << "\n";
        return kNoLink;
    }
    if (!first.answer->value("ok", false)) {
        std::cerr << "airsegctl: refused: " << first.answer->value("error", std::string("no reason given"))
                  << "\n";
        if (o.json) {
            std::cout << first.answer->dump() << "\n";
        }
        return kRefused;
    }
    const auto state = (*first.answer)["result"].value("state", std::string("?"));
    auto source = StickSource::open(j.device, error);
    if (!source) {
        std::cerr << "airsegctl: " << error << "\n";
        return 2;
    }
    if (!o.json) {
        std::cerr << "vehicle acknowledged joystick control (state " << state << "); "
                  << (source->keyboard() ? "w/s/a/d or arrows drive, space centres, q quits"
                                         : "driving from " + j.device)
                  << "\r\n";
    }
    groundside::WatchState view;
    auto take = [&view](const proto::Message& m) { view.take(m, Clock::now()); };
    const auto period =
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::duration<double>(1.0 / j.rate_hz));
    const auto started = Clock::now();
    std::uint64_t sent = 0;
    bool device_gone = false;
    while (g_stop == 0 && !expired(o, started)) {
        if (!source->poll()) {
            device_gone = true;
            break;
        }
        const Stick s = source->stick();
        if (s.quit) {
            break;
        }
        radio.send_joystick(s.steering, s.throttle);
        ++sent;
        radio.run_for(period, take);
        if (!o.json && ::isatty(STDERR_FILENO) == 1) {
            const auto& t = view.latest();
            std::cerr << fmt::format("\rsteering {:+.2f} throttle {:+.2f}  {} {:.1f} m/s  link {}\x1b[K",
                                     s.steering, s.throttle,
                                     t ? proto::vehicle_state_name(t->vehicle_state) : "?",
                                     t ? t->ground_speed_mps : 0.0, radio.link_up() ? "up" : "DOWN");
        }
    }
    // Let the last input leave before the process (and its transport) goes.
    radio.run_for(std::chrono::milliseconds(200), take);
    const std::string why = device_gone ? "the input device closed" : "stopped";
    if (o.json) {
        std::cout << dump_text(nlohmann::json{{"inputs_sent", sent}, {"ended", why}}) << "\n";
    } else {
        std::cerr << "\r\n"
                  << why << " after " << sent
                  << " inputs; the vehicle releases the override after its input timeout\n";
    }
    return kDone;
}

}  // namespace airseg::client
