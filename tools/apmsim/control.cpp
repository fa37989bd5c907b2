#include "tools/apmsim/control.hpp"

#include <sstream>
#include <vector>

#include "cli/values.hpp"

namespace airseg::apmsim {

namespace {

std::vector<std::string> words(std::string_view text) {
    std::istringstream in{std::string(text)};
    std::vector<std::string> out;
    for (std::string w; in >> w;) {
        out.push_back(w);
    }
    return out;
}

double seconds_since(TimePoint start, TimePoint t) {
    return std::chrono::duration<double>(t - start).count();
}

}  // namespace

nlohmann::json state_json(const RoverSim& sim, TimePoint now) {
    const SimState s = sim.state();
    nlohmann::json j{
        {"t", seconds_since(sim.started(), now)},
        {"phase", phase_name(s.phase)},
        {"mode", mode_name(s.mode)},
        {"armed", s.armed},
        {"lat", s.position.lat},
        {"lon", s.position.lon},
        {"heading", s.heading_deg},
        {"speed", s.speed},
        {"current_seq", s.current_seq},
        {"mission_count", s.mission_count},
        {"time_boot_ms", s.time_boot_ms},
        {"boots", s.boots},
        {"battery_remaining", s.battery_remaining},
        {"odometer", s.odometer},
        {"reached", sim.reached().size()},
        {"cruise_speed", s.cruise_speed},
        {"firmware", firmware_name(sim.config().firmware.firmware)},
        {"frozen", sim.frozen()},
        {"gps_fix", s.gps_fix},
        {"failing_check",
         s.failing_check.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.failing_check)},
        {"restarts", sim.counters().auto_restarts},
    };
    if (s.target) {
        j["target"] = {{"lat", s.target->lat}, {"lon", s.target->lon}, {"distance", s.target_distance}};
    } else {
        j["target"] = nullptr;
    }
    return j;
}

nlohmann::json modes_json(const RoverSim& sim) {
    nlohmann::json list = nlohmann::json::array();
    for (const ModeChange& m : sim.mode_history()) {
        list.push_back({{"t", seconds_since(sim.started(), m.at)},
                        {"from", mode_name(m.from)},
                        {"to", mode_name(m.to)},
                        {"cause", m.cause},
                        {"seq", m.current_seq},
                        {"count", m.mission_count}});
    }
    return list;
}

nlohmann::json reached_json(const RoverSim& sim, std::uint64_t from, std::uint64_t count) {
    const auto& log = sim.reached();
    const std::uint64_t first = sim.reached_total() - log.size();  // number of log.front()
    nlohmann::json list = nlohmann::json::array();
    for (std::uint64_t n = std::max(from, first); n < sim.reached_total() && list.size() < count; ++n) {
        const ReachedEvent& r = log[static_cast<std::size_t>(n - first)];
        list.push_back({{"n", n},
                        {"t", seconds_since(sim.started(), r.at)},
                        {"seq", r.seq},
                        {"lat", r.item.lat},
                        {"lon", r.item.lon},
                        {"distance", r.distance},
                        {"passed", r.passed},
                        {"leg_s", r.leg_s},
                        {"median_speed", r.median_speed},
                        {"command", r.command}});
    }
    return {{"total", sim.reached_total()}, {"first_kept", first}, {"reached", list}};
}

nlohmann::json speeds_json(const RoverSim& sim, std::uint64_t from, std::uint64_t count) {
    const auto& log = sim.speed_log();
    const std::uint64_t first = sim.speed_log_total() - log.size();
    nlohmann::json list = nlohmann::json::array();
    for (std::uint64_t n = std::max(from, first); n < sim.speed_log_total() && list.size() < count; ++n) {
        const SpeedChange& c = log[static_cast<std::size_t>(n - first)];
        list.push_back({{"n", n},
                        {"t", seconds_since(sim.started(), c.at)},
                        {"speed", c.speed},
                        {"cause", c.cause},
                        {"seq", c.seq}});
    }
    return {{"total", sim.speed_log_total()}, {"first_kept", first}, {"speeds", list}};
}

nlohmann::json stats_json(const RoverSim& sim) {
    const SimCounters& c = sim.counters();
    const MissionServerStats& m = sim.mission_stats();
    auto long_gaps = nlohmann::json::array();
    for (const HeartbeatGap& g : sim.long_heartbeat_gaps()) {
        long_gaps.push_back({{"t", seconds_since(sim.started(), g.at)},
                             {"s", std::chrono::duration<double>(g.length).count()}});
    }
    return {{"bytes_in", c.bytes_in},
            {"bytes_out", c.bytes_out},
            {"bytes_lost", c.bytes_lost},
            {"bytes_corrupted", c.bytes_corrupted},
            {"frames_in", c.frames_in},
            {"frames_ignored", c.frames_ignored},
            {"bad_checksum", c.bad_checksum},
            {"mavlink2_ignored", c.mavlink2_ignored},
            {"heartbeats_sent", c.heartbeats_sent},
            {"heartbeats_stalled", c.heartbeats_stalled},
            {"auto_restarts", c.auto_restarts},
            {"arm_refused", c.arm_refused},
            {"heartbeat_gap_max_s", std::chrono::duration<double>(c.heartbeat_gap_max).count()},
            {"long_heartbeat_gaps", long_gaps},
            {"uploads_completed", m.uploads_completed},
            {"uploads_cancelled", m.uploads_cancelled},
            {"mission_rerequests", m.rerequests},
            {"mission_items_sent", m.items_sent},
            {"mission_items_received", m.items_received},
            {"mission_denied", m.denied}};
}

std::string apply_control(RoverSim& sim, std::string_view command, TimePoint now, const LinkControl& link) {
    const auto w = words(command);
    if (w.empty()) {
        return "error: empty command";
    }
    const std::string& verb = w[0];
    const auto need = [&](std::size_t n, const char* form) {
        if (w.size() != n) {
            throw cli::UsageError(std::string("usage: ") + form);
        }
    };
    try {
        if (verb == "state") {
            return state_json(sim, now).dump();
        }
        if (verb == "modes") {
            if (w.size() == 1) {
                return modes_json(sim).dump();
            }
            need(2, "modes [LAST_N]");
            const auto n = cli::parse_unsigned(verb, w[1], 1, UINT32_MAX);
            auto all = modes_json(sim);
            const auto skip = all.size() > n ? all.size() - n : 0;
            return nlohmann::json(all.begin() + static_cast<std::ptrdiff_t>(skip), all.end()).dump();
        }
        if (verb == "reached") {
            // Paged: a datagram holds a few hundred entries comfortably.
            if (w.size() > 3) {
                throw cli::UsageError("usage: reached [FROM [COUNT]]");
            }
            const auto from = w.size() > 1 ? cli::parse_unsigned(verb, w[1], 0, UINT64_MAX) : 0;
            const auto count = w.size() > 2 ? cli::parse_unsigned(verb, w[2], 1, 500) : 500;
            return reached_json(sim, from, count).dump();
        }
        if (verb == "speeds") {
            if (w.size() > 3) {
                throw cli::UsageError("usage: speeds [FROM [COUNT]]");
            }
            const auto from = w.size() > 1 ? cli::parse_unsigned(verb, w[1], 0, UINT64_MAX) : 0;
            const auto count = w.size() > 2 ? cli::parse_unsigned(verb, w[2], 1, 500) : 500;
            return speeds_json(sim, from, count).dump();
        }
        if (verb == "stats") {
            return stats_json(sim).dump();
        }
        if (verb == "rcpilot") {
            need(2, "rcpilot MODE");
            const auto mode = parse_mode(w[1]);
            if (!mode || *mode == RoverMode::Initialising) {
                return "error: rcpilot: unknown mode '" + w[1] + "'";
            }
            if (!sim.rc_pilot(*mode, now)) {
                return "error: rcpilot: " + std::string(mode_name(*mode)) + " refused (" +
                       std::string(phase_name(sim.state().phase)) + ")";
            }
            return "ok mode " + std::string(mode_name(*mode));
        }
        if (verb == "mode") {
            need(2, "mode MODE");
            const auto mode = parse_mode(w[1]);
            if (!mode || *mode == RoverMode::Initialising) {
                return "error: mode: unknown mode '" + w[1] + "'";
            }
            if (!sim.force_mode(*mode, now)) {
                return "error: mode: " + std::string(mode_name(*mode)) + " refused (" +
                       std::string(phase_name(sim.state().phase)) + ", firmware " +
                       std::string(firmware_name(sim.config().firmware.firmware)) + ")";
            }
            return "ok mode " + std::string(mode_name(sim.state().mode));
        }
        if (verb == "reboot") {
            if (w.size() == 1) {
                sim.reboot(now);
                return "ok rebooting";
            }
            need(2, "reboot [SECONDS]");
            sim.schedule_reboot(now + cli::parse_seconds(verb, w[1]));
            return "ok reboot in " + w[1] + " s";
        }
        if (verb == "unplug") {
            need(1, "unplug");
            return link.unplug ? link.unplug() : "error: unplug: no link";
        }
        if (verb == "replug") {
            need(1, "replug");
            return link.replug ? link.replug() : "error: replug: no link";
        }
        if (verb == "hbstall") {
            need(2, "hbstall SECONDS");
            sim.stall_heartbeats(cli::parse_seconds(verb, w[1]), now);
            return "ok no heartbeats for " + w[1] + " s";
        }
        if (verb == "loss") {
            if (w.size() != 2 && w.size() != 3) {
                throw cli::UsageError("usage: loss P [BURST]");
            }
            const double p = cli::parse_probability(verb, w[1]);
            const double burst = w.size() == 3 ? cli::parse_double(verb, w[2], 1, 10000) : 1.0;
            sim.faults().loss = p;
            sim.faults().loss_burst = burst;
            return "ok loss " + w[1] + (w.size() == 3 ? " in bursts of " + w[2] + " bytes" : "");
        }
        if (verb == "corrupt") {
            need(2, "corrupt P");
            sim.faults().corrupt = cli::parse_probability(verb, w[1]);
            return "ok corrupt " + w[1];
        }
        if (verb == "ignore-mission") {
            need(2, "ignore-mission on|off");
            if (w[1] != "on" && w[1] != "off") {
                return "error: ignore-mission: expected on or off, got '" + w[1] + "'";
            }
            sim.faults().ignore_mission = w[1] == "on";
            return "ok ignore-mission " + w[1];
        }
        if (verb == "freeze") {
            need(2, "freeze on|off");
            if (w[1] != "on" && w[1] != "off") {
                return "error: freeze: expected on or off, got '" + w[1] + "'";
            }
            sim.freeze(w[1] == "on", now);
            return "ok freeze " + w[1];
        }
        if (verb == "arm") {
            if (w.size() > 2 || (w.size() == 2 && w[1] != "force")) {
                throw cli::UsageError("usage: arm [force]");
            }
            const auto result = sim.arm(true, w.size() == 2, now);
            return result == 0 ? "ok armed"
                               : "error: arm: refused (MAV_RESULT " + std::to_string(result) + ")";
        }
        if (verb == "disarm") {
            need(1, "disarm");
            sim.arm(false, false, now);
            return "ok disarmed";
        }
        if (verb == "gps") {
            need(2, "gps lose|fix");
            if (w[1] != "lose" && w[1] != "fix") {
                return "error: gps: expected lose or fix, got '" + w[1] + "'";
            }
            sim.set_gps_fix(w[1] == "fix", now);
            return "ok gps " + w[1];
        }
        if (verb == "fail-check") {
            if (w.size() < 2) {
                throw cli::UsageError("usage: fail-check REASON...|off");
            }
            if (w.size() == 2 && w[1] == "off") {
                sim.fail_check("", now);
                return "ok fail-check off";
            }
            // The reason as the board would word it: the words after the verb, one space apart.
            std::string reason = w[1];
            for (std::size_t i = 2; i < w.size(); ++i) {
                reason += " " + w[i];
            }
            sim.fail_check(reason, now);
            return "ok fail-check " + reason;
        }
        if (verb == "battery") {
            need(2, "battery full");
            if (w[1] != "full") {
                return "error: battery: expected full, got '" + w[1] + "'";
            }
            sim.swap_battery(now);
            return "ok battery full";
        }
        if (verb == "slow") {
            need(2, "slow MS");
            sim.faults().slow = cli::parse_milliseconds(verb, w[1]);
            return "ok slow " + w[1] + " ms";
        }
        if (verb == "param") {
            if (w.size() == 2) {
                const auto i = sim.params().index_of(w[1]);
                if (!i) {
                    return "error: param: unknown parameter '" + w[1] + "'";
                }
                return nlohmann::json{{"name", w[1]}, {"value", sim.params().at(*i).value}}.dump();
            }
            need(3, "param NAME [VALUE]");
            const double v = cli::parse_double(verb, w[2], -1e9, 1e9);
            if (!sim.set_param(w[1], static_cast<float>(v), now)) {
                return "error: param: unknown parameter '" + w[1] + "'";
            }
            return "ok param " + w[1] + " " + w[2];
        }
        if (verb == "help") {
            return "ok commands: state, modes [N], reached [FROM [COUNT]], speeds [FROM [COUNT]], stats, "
                   "rcpilot MODE, mode MODE, reboot [S], unplug, replug, hbstall S, loss P [BURST], corrupt "
                   "P, "
                   "ignore-mission on|off, freeze on|off, battery full, slow MS, param NAME [VALUE], arm "
                   "[force], "
                   "disarm, "
                   "gps lose|fix, fail-check REASON...|off";
        }
        return "error: unknown command '" + verb + "' (try help)";
    } catch (const cli::UsageError& e) {
        return std::string("error: ") + e.what();
    }
}

}  // namespace airseg::apmsim
