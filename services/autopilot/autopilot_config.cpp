#include "services/autopilot/autopilot_config.hpp"

#include <set>
#include <sstream>

#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::autopilot {

const char* to_string(Board b) {
    switch (b) {
        case Board::Apm2:
            return "apm2";
        case Board::Pixhawk:
            return "pixhawk";
    }
    return "?";
}

const char* to_string(ArmingPolicy p) {
    switch (p) {
        case ArmingPolicy::Auto:
            return "auto";
        case ArmingPolicy::Never:
            return "never";
    }
    return "?";
}

std::optional<std::uint32_t> message_id(std::string_view name) {
    if (const auto* info = mavlink::find_dialect_message(name)) {
        return info->id;
    }
    return std::nullopt;
}

AutopilotConfig AutopilotConfig::defaults_for(Board board) {
    AutopilotConfig c;
    c.board = board;
    if (board == Board::Apm2) {
        c.bauds = {115200};
        c.reset_on_open = true;
        c.mavlink_version = 1;
        c.use_message_interval = false;
        c.mission.use_int = false;  // ArduRover 2.x answers MISSION_REQUEST with MISSION_ITEM
        c.stream_rates = {{DataStream::ExtendedStatus, 2}, {DataStream::Position, 4},
                          {DataStream::Extra1, 4},         {DataStream::Extra2, 4},
                          {DataStream::Extra3, 1},         {DataStream::RcChannels, 2}};
    } else {
        c.bauds = {57600, 115200, 921600};
        c.reset_on_open = false;
        c.mavlink_version = 2;
        c.use_message_interval = true;
        c.mission.use_int = true;
        c.message_rates = {{33, 4.0}, {30, 4.0}, {74, 4.0}, {1, 2.0},
                           {24, 2.0}, {42, 1.0}, {2, 1.0},  {65, 2.0}};
    }
    return c;
}

namespace {
template <class D>
double secs(D d) {
    return std::chrono::duration<double>(d).count();
}
void check_range(std::vector<std::string>& out, const char* key, double v, double lo, double hi,
                 const char* unit = "") {
    if (!(v >= lo && v <= hi)) {
        std::ostringstream os;
        os << key << ": " << v << unit << " is outside " << lo << ".." << hi << unit;
        out.push_back(os.str());
    }
}
}  // namespace

std::vector<std::string> AutopilotConfig::validate(const AutopilotConfig& c) {
    std::vector<std::string> out;
    static const std::set<unsigned> kBauds = {9600,   19200,  38400,  57600,  111100, 115200,
                                              230400, 460800, 500000, 921600, 1500000};
    if (c.bauds.empty()) {
        out.push_back("autopilot.bauds: at least one baud rate is needed");
    }
    for (unsigned b : c.bauds) {
        if (!kBauds.contains(b)) {
            out.push_back("autopilot.bauds: " + std::to_string(b) + " is not a supported baud rate");
        }
    }
    check_range(out, "autopilot.baud_probe", secs(c.baud_probe), 0.5, 30, " s");
    check_range(out, "autopilot.boot_timeout", secs(c.boot_timeout), 1, 120, " s");
    check_range(out, "autopilot.heartbeat_timeout", secs(c.heartbeat_timeout), 0.5, 30, " s");
    if (c.mavlink_version != 1 && c.mavlink_version != 2) {
        out.push_back("autopilot.mavlink_version: must be 1 or 2, not " + std::to_string(c.mavlink_version));
    }
    if (c.target_sysid == 0) {
        out.push_back("autopilot.target_sysid: 0 is the broadcast id, give the autopilot's own id");
    }
    if (c.own_sysid == c.target_sysid && c.own_compid == c.target_compid) {
        out.push_back("autopilot.own_sysid/own_compid: same identity as the autopilot");
    }
    for (const auto& s : c.stream_rates) {
        check_range(out, "autopilot.streams", s.hz, 0, 50, " Hz");
    }
    for (const auto& m : c.message_rates) {
        check_range(out, "autopilot.message_rates", m.hz, 0, 100, " Hz");
    }
    std::set<std::string> seen;
    for (const auto& p : c.params) {
        if (p.name.empty() || p.name.size() > 16) {
            out.push_back("autopilot.params: parameter name \"" + p.name + "\" must be 1..16 characters");
        }
        if (!seen.insert(p.name).second) {
            out.push_back("autopilot.params: " + p.name + " is given twice");
        }
    }
    check_range(out, "autopilot.param_timeout", secs(c.param_timeout), 0.1, 10, " s");
    check_range(out, "autopilot.param_retries", c.param_retries, 0, 20);
    check_range(out, "autopilot.param_list_timeout", secs(c.param_list_timeout), 5, 600, " s");
    check_range(out, "autopilot.mode_timeout", secs(c.mode_timeout), 0.1, 10, " s");
    check_range(out, "autopilot.mode_retries", c.mode_retries, 0, 20);
    check_range(out, "autopilot.reset.unresponsive_timeout", secs(c.unresponsive_timeout), 2, 600, " s");
    check_range(out, "autopilot.reset.max_pulses", c.max_reset_pulses, 0, 20);
    const auto& m = c.mission;
    check_range(out, "autopilot.mission.min_timeout", secs(m.min_timeout), 0.05, 10, " s");
    check_range(out, "autopilot.mission.max_timeout", secs(m.max_timeout), secs(m.min_timeout), 60, " s");
    check_range(out, "autopilot.mission.initial_timeout", secs(m.initial_timeout), secs(m.min_timeout),
                secs(m.max_timeout), " s");
    check_range(out, "autopilot.mission.retries", m.retries, 0, 50);
    check_range(out, "autopilot.mission.give_up_after", secs(m.give_up_after), 0, 300, " s");
    check_range(out, "autopilot.mission.vehicle_gives_up", secs(m.vehicle_gives_up), 1, 120, " s");
    check_range(out, "autopilot.mission.max_items", m.max_items, 2, 65535);
    const auto& r = c.rc_override;
    check_range(out, "autopilot.rc_override.rate_hz", r.rate_hz, 1, 50, " Hz");
    check_range(out, "autopilot.rc_override.input_timeout", secs(r.input_timeout), 0.1, 5, " s");
    check_range(out, "autopilot.rc_override.steering_channel", r.steering_channel, 1, 8);
    check_range(out, "autopilot.rc_override.throttle_channel", r.throttle_channel, 1, 8);
    if (r.steering_channel == r.throttle_channel) {
        out.push_back("autopilot.rc_override: steering and throttle use the same channel");
    }
    if (!(800 <= r.pwm_min && r.pwm_min < r.pwm_trim && r.pwm_trim < r.pwm_max && r.pwm_max <= 2200)) {
        out.push_back("autopilot.rc_override: need 800 <= pwm_min < pwm_trim < pwm_max <= 2200");
    }
    check_range(out, "autopilot.rc_override.release_repeats", r.release_repeats, 1, 10);
    return out;
}

}  // namespace airseg::autopilot
