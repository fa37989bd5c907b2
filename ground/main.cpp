// airseg-ground: the ground station hub. Owns the radio link to the vehicle and serves airsegctl clients
// (watchers and one commanding operator at a time) on a Unix socket and optionally TCP.
// docs/ground-station.md.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <csignal>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/command_line.hpp"
#include "ground/fleet_bridge.hpp"
#include "ground/gcs_feed.hpp"
#include "ground/hub.hpp"
#include "ground/map_feed.hpp"
#include "groundside/mqtt_options.hpp"
#include "groundside/mqtt_session.hpp"
#include "groundside/radio_options.hpp"

namespace {

const char* const kUsageHead =
    "Usage: airseg-ground (--link PATH[,PATH2] | --udp HOST:PORT) [OPTIONS]\n"
    "\n"
    "The ground station hub: keeps the one radio session to the vehicle and serves local clients.\n"
    "airsegctl --ground talks through it: any number of watchers and one commanding operator at a time,\n"
    "each command acknowledged by the vehicle.\n"
    "\n";

const char* const kUsageTail =
    "\n"
    "Roles: a client that proves the control key (airsegctl --key, the hub's own --key) may take control;\n"
    "one client holds it at a time. Every other client is a monitor: it sees everything, and the vehicle\n"
    "runs its commands with monitor rights only. A hub without --key grants control to Unix-socket\n"
    "clients (the socket is mode 0660: owner and --socket-group), never to TCP ones.\n"
    "\n"
    "Exit codes: 0 stopped by SIGINT/SIGTERM, 1 could not start, 2 usage.\n";

struct Options {
    airseg::ground::HubConfig hub;
    airseg::ground::MapConfig map;
    airseg::ground::GcsConfig gcs;
    airseg::ground::FleetConfig fleet;
    bool mqtt_given = false;  // --mqtt: the fleet bridge runs
    bool radio_given = false;
    std::string log_level = "info";
};

/// The MQTT options together; an error for people or empty.
std::string check_fleet(Options& o) {
    const auto& m = o.fleet.mqtt;
    if (!o.mqtt_given) {
        const bool any = !o.fleet.vehicle.empty() || !m.username.empty() || !m.password_file.empty() ||
                         !m.ca_file.empty() || !m.cert_file.empty() || !m.key_file.empty();
        return any ? "--vehicle and the --mqtt-* options need --mqtt HOST[:PORT]" : "";
    }
    if (o.fleet.vehicle.empty()) {
        return "--mqtt needs --vehicle ID";
    }
    if (auto problem = airseg::groundside::check_mqtt_options(m); !problem.empty()) {
        return problem;
    }
    o.fleet.hub_version = std::string("airseg-ground ") + AIRSEG_VERSION;
    return {};
}

}  // namespace

int main(int argc, char** argv) {
    using namespace airseg::cli;
    Options o;
    OptionTable table("Options");
    airseg::groundside::add_radio_options(table, o.hub.radio, [&o] { o.radio_given = true; });
    table
        .value(
            "socket", "PATH",
            "Unix socket for clients (default /run/airseg-ground/ground.sock; 'off' for none)",
            [&o](std::string_view, std::string_view v) { o.hub.socket = v == "off" ? "" : std::string(v); })
        .value("socket-group", "NAME",
               "group allowed to connect to the socket (mode 0660; default the hub's)",
               text(o.hub.socket_group))
        .value("tcp", "HOST:PORT", "also serve clients over TCP (off by default)", text(o.hub.tcp))
        .value(
            "map", "HOST:PORT",
            "serve the live map here (default 127.0.0.1:8080; 'off' for none; port 0 picks one)",
            [&o](std::string_view, std::string_view v) { o.map.listen = v == "off" ? "" : std::string(v); })
        .flag("map-control",
              "let the map's buttons load, pause, resume and skip the plan (default: view only)",
              [&o] { o.map.control = true; })
        .value("map-host", "NAME",
               "a host name the map answers to, besides its addresses and localhost (repeatable; others are "
               "refused)",
               [&o](std::string_view, std::string_view v) { o.map.host_names.emplace_back(v); })
        .value("map-tiles", "URL",
               "tile server for the map, e.g. https://tile.openstreetmap.org/{z}/{x}/{y}.png (default: an "
               "offline grid)",
               text(o.map.tile_url))
        .value(
            "mavlink-udp", "HOST:PORT",
            "send the vehicle's MAVLink here, where ground stations listen (default 127.0.0.1:14550; 'off')",
            [&o](std::string_view, std::string_view v) { o.gcs.udp_to = v == "off" ? "" : std::string(v); })
        .value(
            "mavlink-udp-listen", "ADDR:PORT",
            "hear ground stations over UDP here (default 127.0.0.1:0, the port the hub sends from; 'off' for "
            "no UDP at all)",
            [&o](std::string_view, std::string_view v) {
                o.gcs.udp_listen = v == "off" ? "" : std::string(v);
            })
        .value("mavlink-tcp", "ADDR:PORT",
               "serve ground stations over TCP here (default 127.0.0.1:5760; 'off'; 0.0.0.0 opens it to the "
               "network)",
               [&o](std::string_view, std::string_view v) { o.gcs.tcp = v == "off" ? "" : std::string(v); });
    airseg::groundside::add_mqtt_options(table, o.fleet.mqtt, o.fleet.vehicle, [&o] { o.mqtt_given = true; });
    table.value("log-level", "LEVEL", "trace, debug, info, warn or error (default info)", text(o.log_level))
        .help_and_version();
    const Program program{"airseg-ground", [&table] { return kUsageHead + describe(table) + kUsageTail; }};
    auto line = run(program, std::vector<std::string>(argv + std::min(argc, 1), argv + argc), table,
                    std::cout, std::cerr, {.max = 0});
    if (line.exit_code) {
        return *line.exit_code;
    }
    if (!o.radio_given) {
        return usage_error(std::cerr, "airseg-ground", "no radio given (--link PATH or --udp HOST:PORT)");
    }
    if (auto problem = airseg::groundside::validate(o.hub.radio); !problem.empty()) {
        return usage_error(std::cerr, "airseg-ground", problem);
    }
    if (auto problem = check_fleet(o); !problem.empty()) {
        return usage_error(std::cerr, "airseg-ground", problem);
    }
    const auto level = spdlog::level::from_str(o.log_level);
    if (level == spdlog::level::off && o.log_level != "off") {
        return usage_error(std::cerr, "airseg-ground", "--log-level: unknown level '" + o.log_level + "'");
    }
    spdlog::set_default_logger(spdlog::stderr_color_mt("airseg-ground"));
    spdlog::set_level(level);

    boost::asio::io_context io;
    auto strand = boost::asio::make_strand(io);
    airseg::ground::Hub hub(strand, o.hub);
    if (auto error = hub.start(); !error.empty()) {
        std::cerr << "airseg-ground: " << error << '\n';
        return 1;
    }
    std::unique_ptr<airseg::ground::GcsFeed> gcs;
    if (!o.gcs.udp_listen.empty() || !o.gcs.tcp.empty()) {
        gcs = std::make_unique<airseg::ground::GcsFeed>(strand, hub, o.gcs);
        if (auto error = gcs->start(); !error.empty()) {
            std::cerr << "airseg-ground: MAVLink for ground stations: " << error << '\n';
            return 1;
        }
        spdlog::info("ground hub: MAVLink for ground stations on {}", gcs->where());
    }
    std::unique_ptr<airseg::ground::MapFeed> map;
    if (!o.map.listen.empty()) {
        map = std::make_unique<airseg::ground::MapFeed>(strand, hub, o.map);
        if (auto error = map->start(); !error.empty()) {
            std::cerr << "airseg-ground: " << error << '\n';
            return 1;
        }
        const auto host = o.map.listen.substr(0, o.map.listen.rfind(':'));
        spdlog::info("ground hub: the map on http://{}:{}/{}", host, map->port(),
                     o.map.control ? " (its buttons command the vehicle)" : "");
    }
    std::unique_ptr<airseg::ground::FleetBridge> fleet;
    if (o.mqtt_given) {
        fleet = std::make_unique<airseg::ground::FleetBridge>(strand, hub, o.fleet);
        if (auto error = fleet->start(); !error.empty()) {
            std::cerr << "airseg-ground: " << error << '\n';
            return 1;
        }
        spdlog::info("ground hub: the fleet on MQTT {}:{} as airseg/{}/", o.fleet.mqtt.host,
                     o.fleet.mqtt.port, o.fleet.vehicle);
    }
    boost::asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code& ec, int) {
        if (!ec) {
            spdlog::info("ground hub: stopping");
            boost::asio::dispatch(strand, [&] {
                if (fleet) {
                    fleet->stop();
                }
                if (map) {
                    map->stop();
                }
                if (gcs) {
                    gcs->stop();
                }
                hub.stop();
                io.stop();
            });
        }
    });
    io.run();
    return 0;
}
