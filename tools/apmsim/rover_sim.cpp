#include "tools/apmsim/rover_sim.hpp"

#include <algorithm>

#include "services/autopilot/mavlink/enums.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::apmsim {

namespace mv = mavlink;

namespace {

constexpr double kIdleAmps = 1.5;

StoredItem home_item(const RoverSimConfig& c) {
    StoredItem h;
    h.frame = 0;  // MAV_FRAME_GLOBAL: home altitude is absolute
    h.lat_e7 = static_cast<std::int32_t>(std::lround(c.home.lat * 1e7));
    h.lon_e7 = static_cast<std::int32_t>(std::lround(c.home.lon * 1e7));
    h.alt = c.home_alt;
    return h;
}

}  // namespace

RoverSimConfig RoverSimConfig::for_firmware(Firmware f) {
    RoverSimConfig c;
    c.firmware = FirmwareProfile::of(f);
    if (f == Firmware::Rover2) {
        c.version = mavlink::Version::V1;
        c.reached_style = ReachedStyle::TextOnly;
        c.mission_rerequest = milliseconds(500);  // "tnow > waypoint_timelast_request + 500"
        c.mission_give_up = seconds(1);           // waypoint_receive_timeout(1000)
    }
    return c;
}

std::vector<std::string> RoverSimConfig::validate(const RoverSimConfig& c) {
    std::vector<std::string> errors;
    if (!c.firmware.reads_mavlink2 && c.version == mavlink::Version::V2) {
        errors.emplace_back("firmware " + std::string(firmware_name(c.firmware.firmware)) +
                            ": a board that reads MAVLink 1 only must send MAVLink 1");
    }
    if (!(c.home.lat >= -89 && c.home.lat <= 89) || !(c.home.lon >= -180 && c.home.lon <= 180)) {
        errors.emplace_back("home: latitude must be within ±89 and longitude within ±180 degrees");
    }
    if (c.mission_capacity < 1 || c.mission_capacity > 65535) {
        errors.emplace_back("mission capacity: must be 1..65535 items (home included)");
    }
    if (c.boot_delay < Duration::zero() || c.calib_time < Duration::zero()) {
        errors.emplace_back("boot delay and calibration time must not be negative");
    }
    if (c.physics_step <= Duration::zero() || c.mission_rerequest <= Duration::zero() ||
        c.mission_give_up <= Duration::zero()) {
        errors.emplace_back("physics step and mission timers must be positive");
    }
    return errors;
}

std::string_view phase_name(BootPhase p) {
    switch (p) {
        case BootPhase::Silent:
            return "silent";
        case BootPhase::Calibrating:
            return "calibrating";
        case BootPhase::Ready:
            return "ready";
    }
    return "?";
}

RoverSim::RoverSim(RoverSimConfig config, TimePoint now)
    : config_(std::move(config)),
      started_(now),
      now_(now),
      rng_(config_.seed),
      params_(ParamTable::for_profile(config_.firmware)),
      store_(config_.mission_capacity, home_item(config_)),
      out_(config_.version),
      server_(store_, out_,
              MissionHooks{
                  [this](std::uint16_t seq) { return set_current(seq, now_); },
                  [this] { return mode_ == RoverMode::Auto && mission_running_; },
                  [this] { mission_changed(); },
                  [this](const StoredItem& item) { return guided_goto(item); },
                  [this] { return home_item(config_); },
                  [this] { return current_seq_; },
              },
              config_.mission_rerequest, config_.mission_give_up),
      legacy_server_(store_, out_,
                     LegacyMissionHooks{
                         [this] { return static_cast<std::uint16_t>(r2_.command_index); },
                         [this](std::uint16_t seq) { r2_change_command(seq, now_); },
                         [this](const StoredItem& item) { r2_guided_goto(item, now_); },
                         [this] { mission_changed(); },
                         [this] { return home_alt_cm(); },
                     },
                     config_.mission_rerequest, config_.mission_give_up),
      vehicle_(config_.home) {
    last_step_ = now;
    new_parser();
    if (rover2_mission()) {
        r2_boot_ready(now);  // the stored home of the last run
    }
    note_speed("power on", now);
    reboot(now);
}

void RoverSim::new_parser() {
    if (config_.firmware.reads_mavlink2) {
        parser_ = std::make_unique<mv::Parser>();
        return;
    }
    // The 2.x message table has no CRC_EXTRA for the _INT mission messages (MAVLink 1 ids only).
    std::vector<std::uint32_t> unknown;
    if (!config_.firmware.mission_int) {
        unknown = {mv::MissionRequestInt::kId, mv::MissionItemInt::kId};
    }
    legacy_parser_ = std::make_unique<LegacyParser>(std::move(unknown));
}

void RoverSim::reboot(TimePoint now) {
    advance(now);
    out_.drop_held();
    server_.reset();
    legacy_server_.reset();
    ftp_.reset();
    streams_.clear();
    if (parsing_) {
        reboot_during_parse_ = true;  // the parser is mid-push: replaced when the push returns
    } else {
        new_parser();
    }
    ++boots_;
    boot_started_ = now;
    reboot_at_ = kNever;
    armed_ = false;
    mission_running_ = false;
    mission_complete_ = false;
    current_seq_ = 0;
    target_.reset();
    leg_start_.reset();
    guided_target_.reset();
    rc_override_.fill(0);
    r2_ = Rover2Nav{};
    planned_speed_ = 0;
    wait_until_.reset();
    change_detector_.reset();
    leg_speeds_.clear();
    // AP_Arming::update() after a boot: no report for 30 s, the checks taken as failing until they run.
    last_prearm_display_ = now;
    prearm_failing_ = true;
    report_immediately_ = false;
    // What was set without saving (a 2.x DO_CHANGE_SPEED) is lost; a DO_CHANGE_SPEED's speed is forgotten.
    for (const auto& [name, saved] : unsaved_params_) {
        params_.set(name, saved);
    }
    unsaved_params_.clear();
    speed_override_.reset();
    if (!speed_log_.empty()) {
        note_speed("reboot", now);
    }
    if (mode_ != RoverMode::Initialising) {
        set_mode(RoverMode::Initialising, "reboot", now);
    }
    enter_phase(BootPhase::Silent, now);
}

void RoverSim::port_opened(TimePoint now) {
    if (config_.reset_on_open) {
        reboot(now);
    }
}

void RoverSim::enter_phase(BootPhase phase, TimePoint now) {
    phase_ = phase;
    switch (phase) {
        case BootPhase::Silent:
            phase_until_ = now + config_.boot_delay;
            next_heartbeat_ = kNever;
            break;
        case BootPhase::Calibrating:
            phase_until_ = now + config_.calib_time;
            next_heartbeat_ = now;
            if (rover2_telemetry()) {
                // system.pde startup_ground() and startup_INS_ground(), with the 2.x severities; the
                // mavlink_delay() callback sends "Initialising APM..." while the board waits.
                r2_text(1, "<startup_ground> GROUND START");
                r2_text(1, "Demo Servos!");
                r2_text(2, "Warming up ADC...");
                r2_text(1, "Initialising APM...");
                r2_text(1, "Demo Servos!");
                r2_text(1, "Demo Servos!");
                r2_text(2, "Beginning INS calibration; do not move vehicle");
                break;
            }
            text(mavlink::kSeverityInfo, "Initialising APM...");
            text(mavlink::kSeverityCritical, "Beginning INS calibration; do not move vehicle");
            break;
        case BootPhase::Ready: {
            phase_until_ = kNever;
            if (rover2_mission()) {
                r2_boot_ready(now);
            }
            const auto initial = mode_from_number(static_cast<std::uint32_t>(params_.get("INITIAL_MODE", 0)));
            set_mode(initial && *initial != RoverMode::Initialising ? *initial : RoverMode::Manual,
                     boots_ == 1 ? "power on" : "reboot", now);
            armed_ = params_.get("ARMING_REQUIRE", 0) == 0;  // no arming step: armed from boot
            load_stream_rates(now);
            if (rover2_telemetry()) {
                r2_text(1, "\n\n Ready to drive.");
                r2_text(1, "init home");  // init_home(), once the GPS has a fix
            } else {
                text(mavlink::kSeverityInfo, "Ready to drive.");
            }
            next_heartbeat_ = now;
            break;
        }
    }
}

void RoverSim::advance(TimePoint now) {
    now = std::max(now, now_);
    // The electronics draw a steady current whether or not the car moves.
    consumed_mah_ += kIdleAmps * std::chrono::duration<double>(now - now_).count() * 1000.0 / 3600.0;
    // Whole physics steps up to `now`; mission events happen at the step that causes them.
    if (frozen_) {
        last_step_ = std::max(last_step_, now);  // not one step: the vehicle must not move at all
    } else if (!physics_active()) {
        last_step_ = std::max(last_step_, now - config_.physics_step);
    }
    while (last_step_ + config_.physics_step <= now) {
        last_step_ += config_.physics_step;
        now_ = last_step_;
        out_.set_reply_context(now_, Duration::zero());
        physics_step(last_step_);
        // The 2.x navigate() / update_commands() tasks at 10 Hz, at the first physics step at or after their
        // time.
        while (r2_.next_tick <= last_step_) {
            r2_.next_tick += milliseconds(100);
            r2_tick(last_step_);
        }
    }
    while (r2_.next_tick <= now) {
        const TimePoint tick = r2_.next_tick;
        r2_.next_tick += milliseconds(100);
        now_ = std::max(now_, tick);
        out_.set_reply_context(now_, Duration::zero());
        r2_tick(tick);
    }
    now_ = now;
}

void RoverSim::handle_timeout(TimePoint now) {
    if (reboot_at_ <= now) {
        reboot(std::max(reboot_at_, now_));
    }
    advance(now);
    if (phase_until_ <= now) {
        enter_phase(phase_ == BootPhase::Silent ? BootPhase::Calibrating : BootPhase::Ready, now);
    }
    if (next_heartbeat_ <= now) {
        const auto sent = counters_.heartbeats_sent;
        send_heartbeat(now);
        if (counters_.heartbeats_sent != sent) {
            note_heartbeat_sent(now);
        }
        arming_update(now);  // AP_Arming::update() runs at 1 Hz too
        next_heartbeat_ = std::max(next_heartbeat_ + seconds(1), now);
    }
    if (phase_ == BootPhase::Ready) {
        for (std::uint32_t id : streams_.take_due(now)) {
            send_stream_message(id, now);
        }
    }
    out_.set_reply_context(now, faults_.slow);
    server_.handle_timeout(now);
    legacy_server_.handle_timeout(now);
    note_speed("param", now);  // a parameter written directly (params())
    out_.release(now);
}

// Whatever silenced the board, its peer saw the silence: a stall fault, a reboot, or (at a speedup) the
// simulator itself not running, which a wake at the end of it shows as one long gap.
void RoverSim::note_heartbeat_sent(TimePoint now) {
    if (last_heartbeat_sent_ != kNever) {
        const Duration gap = now - last_heartbeat_sent_;
        counters_.heartbeat_gap_max = std::max(counters_.heartbeat_gap_max, gap);
        if (gap > kLongHeartbeatGap) {
            if (long_heartbeat_gaps_.size() == kMaxHeartbeatGaps) {
                long_heartbeat_gaps_.pop_front();
            }
            long_heartbeat_gaps_.push_back({now, gap});
        }
    }
    last_heartbeat_sent_ = now;
}

TimePoint RoverSim::poll_timeout() const {
    TimePoint t = std::min({phase_until_, next_heartbeat_, reboot_at_, out_.next_release(),
                            server_.poll_timeout(), legacy_server_.poll_timeout(), r2_.next_tick});
    if (phase_ == BootPhase::Ready) {
        t = std::min(t, streams_.next_due());
    }
    if (physics_active()) {
        t = std::min(t, last_step_ + config_.physics_step);
    }
    return t;
}

void RoverSim::handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now) {
    handle_timeout(now);
    counters_.bytes_in += bytes.size();
    std::vector<std::uint8_t> in(bytes.begin(), bytes.end());
    impair(in, burst_in_);
    if (phase_ == BootPhase::Silent || in.empty()) {
        return;  // the boot loader and the early start-up do not read MAVLink
    }
    parsing_ = true;
    const auto on_frame = [&](const mv::Frame& f) {
        if (reboot_during_parse_) {
            return;  // the board went down: the rest of this input meets the boot loader
        }
        ++counters_.frames_in;
        out_.set_reply_context(now, faults_.slow);
        dispatch(f, now);
    };
    if (legacy_parser_) {
        const LegacyParserStats before = legacy_parser_->stats();
        legacy_parser_->push(in, on_frame);
        counters_.bad_checksum += legacy_parser_->stats().bad_crc - before.bad_crc;
        counters_.mavlink2_ignored += legacy_parser_->stats().v2_starts - before.v2_starts;
    } else {
        const std::uint64_t before = parser_->stats().bad_checksum;
        parser_->push(in, on_frame);
        counters_.bad_checksum += parser_->stats().bad_checksum - before;
    }
    parsing_ = false;
    if (reboot_during_parse_) {
        reboot_during_parse_ = false;
        new_parser();
    }
    note_speed("param", now);
    out_.release(now);
}

std::vector<std::uint8_t> RoverSim::poll_transmit() {
    auto bytes = out_.take();
    impair(bytes, burst_out_);
    counters_.bytes_out += bytes.size();
    return bytes;
}

void RoverSim::dispatch(const mv::Frame& f, TimePoint now) {
    if (!config_.firmware.mission_int &&
        (f.msgid == mv::MissionRequestInt::kId || f.msgid == mv::MissionItemInt::kId)) {
        ++counters_.frames_ignored;  // a firmware without the _INT mission messages
        return;
    }
    const bool mission_frame = f.msgid == mv::MissionRequestList::kId || f.msgid == mv::MissionRequest::kId ||
                               f.msgid == mv::MissionRequestInt::kId || f.msgid == mv::MissionCount::kId ||
                               f.msgid == mv::MissionItem::kId || f.msgid == mv::MissionItemInt::kId ||
                               f.msgid == mv::MissionWritePartialList::kId ||
                               f.msgid == mv::MissionClearAll::kId || f.msgid == mv::MissionSetCurrent::kId ||
                               f.msgid == mv::MissionAck::kId;
    if (mission_frame) {
        if (faults_.ignore_mission) {
            ++counters_.frames_ignored;
            return;
        }
        if (rover2_mission()) {
            legacy_server_.handle(f, now);
        } else {
            server_.handle(f, now);
        }
        return;
    }
    switch (f.msgid) {
        case mv::ParamRequestList::kId:
        case mv::ParamRequestRead::kId:
        case mv::ParamSet::kId:
            on_param(f);
            return;
        case mv::CommandLong::kId:
            on_command_long(f, now);
            return;
        case mv::CommandInt::kId:
            on_command_int(f, now);
            return;
        case mv::Timesync::kId:
            on_timesync(f, now);
            return;
        case mv::SetPositionTargetGlobalInt::kId:
            on_set_position_target(f);
            return;
        case mv::FileTransferProtocol::kId:
            on_ftp(f);
            return;
        case mv::SetMode::kId:
            on_set_mode(f, now);
            return;
        case mv::RequestDataStream::kId:
            on_request_data_stream(f, now);
            return;
        case mv::RcChannelsOverride::kId:
            on_rc_override(f, now);
            return;
        default:
            ++counters_.frames_ignored;  // heartbeats of the GCS and everything the board does not serve
            return;
    }
}

double RoverSim::uniform() {
    return static_cast<double>(rng_() >> 11) * 0x1.0p-53;
}

void RoverSim::impair(std::vector<std::uint8_t>& bytes, bool& in_burst) {
    if (faults_.loss <= 0 && faults_.corrupt <= 0) {
        return;
    }
    std::vector<std::uint8_t> kept;
    kept.reserve(bytes.size());
    for (std::uint8_t b : bytes) {
        if (lose_byte(in_burst)) {
            ++counters_.bytes_lost;
            continue;
        }
        if (faults_.corrupt > 0 && uniform() < faults_.corrupt) {
            ++counters_.bytes_corrupted;
            b = static_cast<std::uint8_t>(b ^ (1U << (rng_() % 8)));
        }
        kept.push_back(b);
    }
    bytes = std::move(kept);
}

// A two-state (Gilbert) channel. In a burst every byte is lost and the burst goes on after each with
// probability 1 - 1/B (mean length B). Outside, a burst starts at a byte with probability p; good runs then
// average (1 - p) / p bytes, and the lost fraction B / (B + (1 - p) / p) equals `loss` for
// p = loss / (B (1 - loss) + loss).
bool RoverSim::lose_byte(bool& in_burst) {
    const double loss = faults_.loss;
    if (loss <= 0) {
        in_burst = false;
        return false;
    }
    const double length = faults_.loss_burst;
    if (length <= 1) {
        return uniform() < loss;
    }
    if (!in_burst && uniform() >= loss / (length * (1.0 - loss) + loss)) {
        return false;
    }
    in_burst = uniform() >= 1.0 / length;
    return true;
}

void RoverSim::text(std::uint8_t severity, std::string_view message) {
    mv::Statustext t;
    t.severity = severity;
    mv::set_text(t.text, message);
    out_.send(t);
}

std::uint32_t RoverSim::time_boot_ms(TimePoint now) const {
    return static_cast<std::uint32_t>(std::chrono::duration_cast<milliseconds>(now - boot_started_).count());
}

std::uint64_t RoverSim::unix_us(TimePoint now) const {
    return config_.unix_time_at_start_us +
           static_cast<std::uint64_t>(std::chrono::duration_cast<microseconds>(now - started_).count());
}

SimState RoverSim::state() const {
    SimState s;
    s.phase = phase_;
    s.mode = mode_;
    s.armed = is_armed();
    s.position = vehicle_.position();
    s.heading_deg = vehicle_.heading() * 180.0 / 3.14159265358979323846;
    s.speed = vehicle_.speed();
    s.current_seq = rover2_mission() ? static_cast<std::uint16_t>(r2_.command_index) : current_seq_;
    s.mission_count = store_.count();
    s.target = target_;
    s.target_distance = target_ ? distance_m(vehicle_.position(), *target_) : 0;
    s.time_boot_ms = time_boot_ms(now_);
    s.boots = boots_;
    const double capacity = std::max(1.0F, params_.get("BATT_CAPACITY", 3300));
    s.battery_remaining = std::clamp(100.0 * (1.0 - consumed_mah_ / capacity), 0.0, 100.0);
    s.odometer = vehicle_.odometer();
    s.cruise_speed = cruise_speed();
    s.gps_fix = gps_fix_;
    s.failing_check = failing_check_;
    return s;
}

double RoverSim::cruise_speed() const {
    // A parameter set to nonsense must not fling the car off the planet.
    const bool wp_speed = config_.firmware.auto_speed == FirmwareProfile::AutoSpeed::WpSpeed;
    const double param =
        std::clamp(static_cast<double>(params_.get(wp_speed ? "WP_SPEED" : "CRUISE_SPEED", 2)), 0.0, 50.0);
    return std::clamp(speed_override_.value_or(param), 0.0, 50.0);
}

void RoverSim::note_speed(const std::string& cause, TimePoint now, std::optional<std::uint16_t> seq) {
    const double speed = cruise_speed();
    if (!speed_log_.empty() && speed_log_.back().speed == speed) {
        return;
    }
    if (speed_log_.size() >= kMaxSpeedLog) {
        speed_log_.pop_front();
    }
    speed_log_.push_back(SpeedChange{now, speed, cause, seq.value_or(state().current_seq)});
    ++speed_log_total_;
}

void RoverSim::set_unsaved_param(const std::string& name, float value) {
    if (const auto i = params_.index_of(name)) {
        unsaved_params_.try_emplace(name, params_.at(*i).value);
        params_.set(name, value);
    }
}

bool RoverSim::set_param(const std::string& name, float value, TimePoint now, const std::string& cause) {
    handle_timeout(now);
    if (!params_.set(name, value)) {
        return false;
    }
    unsaved_params_.erase(name);
    apply_param_side_effects(name, cause, now);
    return true;
}

}  // namespace airseg::apmsim
