#include "services/autopilot/ardupilot/driver.hpp"

#include <algorithm>
#include <cmath>

#include "services/autopilot/ardupilot/mission_codec.hpp"
#include "services/autopilot/ardupilot/rover_modes.hpp"
#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {

namespace mav = airseg::mavlink;

namespace {

double seconds_between(TimePoint a, TimePoint b) {
    return std::chrono::duration<double>(b - a).count();
}

RequestResult from_mission(MissionResult r) {
    switch (r) {
        case MissionResult::Success:
            return RequestResult::Ok;
        case MissionResult::Timeout:
            return RequestResult::Timeout;
        case MissionResult::Denied:
        case MissionResult::NoSpace:
            return RequestResult::Refused;
        case MissionResult::InvalidArgument:
            return RequestResult::Invalid;
        case MissionResult::Cancelled:
            return RequestResult::Cancelled;
        case MissionResult::Busy:
            return RequestResult::Busy;
    }
    return RequestResult::Refused;
}

bool has_stop(const std::vector<MissionItem>& items) {
    return std::any_of(items.begin(), items.end(),
                       [](const MissionItem& m) { return m.kind == MissionItem::Kind::Stop; });
}
}  // namespace

const char* to_string(Phase p) {
    switch (p) {
        case Phase::Closed:
            return "closed";
        case Phase::WaitBoot:
            return "wait_boot";
        case Phase::Params:
            return "params";
        case Phase::Mission:
            return "mission";
        case Phase::ApplyParams:
            return "apply_params";
        case Phase::Ready:
            return "ready";
    }
    return "?";
}

Driver::Driver(AutopilotConfig config)
    : config_(std::move(config)),
      out_(config_.own_sysid, config_.own_compid,
           config_.mavlink_version == 1 ? mav::Version::V1 : mav::Version::V2),
      missions_(out_, config_.target_sysid, config_.target_compid, config_.mission),
      params_(out_, config_.target_sysid, config_.target_compid,
              ParamClientConfig{config_.param_timeout, config_.param_retries, config_.param_list_timeout}),
      rc_(config_.rc_override, config_.target_sysid, config_.target_compid),
      link_(LinkWatchConfig{config_.bauds, config_.baud_probe, config_.reset_on_open, config_.boot_timeout,
                            config_.heartbeat_timeout, config_.unresponsive_timeout,
                            config_.max_reset_pulses}),
      modes_(config_.mode_timeout, config_.mode_retries),
      arming_(config_.mode_timeout, config_.mode_retries) {}

// --- port lifecycle ----------------------------------------------------------------------------------------

void Driver::on_port_open(TimePoint now) {
    link_.on_port_open(now);
    sequence_start_ = now;
    ready_s_.reset();
    parser_ = mav::Parser{};
    missions_.forget_board();  // another board may be behind the port now
    stop_as_jump_ = false;
    auto_check_.cancel();
    forget_speed();
    armed_seen_ = false;
    speed_by_param_ = config_.board == Board::Apm2;  // ArduRover 2.x has no MAV_CMD_DO_CHANGE_SPEED command
    next_gcs_heartbeat_ = config_.gcs_heartbeat ? now : kNever;
    enter(Phase::WaitBoot, now);
}

void Driver::on_port_closed(const std::string& reason, TimePoint now) {
    auto_check_.cancel();
    cancel_everything("autopilot port closed: " + reason, now);
    if (link_.on_port_closed()) {
        emit(LinkDown{reason});
    }
    phase_ = Phase::Closed;
    phase_deadline_ = kNever;
    next_gcs_heartbeat_ = kNever;
    last_error_ = reason;
    update_state(now, false);
}

void Driver::on_port_reopened(TimePoint now) {
    if (!link_.port_open()) {
        on_port_open(now);
        return;
    }
    parser_ = mav::Parser{};
}

void Driver::on_reset_pulsed(TimePoint now) {
    link_.on_reset_pulsed(now);
    cancel_everything("autopilot reset", now);
    enter(Phase::WaitBoot, now);
}

// --- plumbing ----------------------------------------------------------------------------------------------

void Driver::handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now) {
    link_.on_bytes(bytes.size(), now);
    parser_.push(bytes, [&](const mav::Frame& f) {
        if (!f.checksum_verified) {
            return;
        }
        tap_incoming(f);  // any verified frame of the dialect may be forwarded
        if (!f.typed) {
            return;  // the driver acts only on the messages it declares (messages.def)
        }
        on_frame(f, now);
        // A request's result goes out in its place among the board's reports: the board reports its target
        // in order with its answers to the writes, and the flight plan tells by that order whether a target
        // report came before or after a write landed. A slow daemon reads many frames at once; finishing the
        // requests only after the whole read put every report of the read before them.
        drain_clients(now);
    });
    drain_clients(now);
    send_gcs_heartbeat_if_due(now);
    flush_rc(now);
}

// On the whole-second grid the daemon's other periodic work uses (time.hpp), and sent with the first input
// after it is due: the board streams several times a second, so the heartbeat costs no wake-up of its own.
// Only a silent board leaves it to the timer, half a second late (kGcsHeartbeatSlack).
void Driver::send_gcs_heartbeat_if_due(TimePoint now) {
    if (now < next_gcs_heartbeat_) {
        return;
    }
    mav::Heartbeat hb;
    hb.type = config_.gcs_heartbeat_type;
    hb.autopilot = 8;      // MAV_AUTOPILOT_INVALID
    hb.system_status = 4;  // MAV_STATE_ACTIVE
    out_.send(hb);
    next_gcs_heartbeat_ = next_on_grid(now, seconds(1));
}

void Driver::handle_timeout(TimePoint now, bool input_waiting) {
    missions_.handle_timeout(now);
    params_.handle_timeout(now);
    drain_clients(now);

    const LinkWatch::Due due = link_.handle_timeout(now, input_waiting);
    if (due.lost) {
        link_lost(*due.lost, due.lost_detail, now);
    }
    if (due.reboot && watching_for_reboots()) {
        reboot_detected(*due.reboot, now);
    }
    if (auto_check_.handle_timeout(now)) {
        report_current(telemetry_.mission_current);  // not back at the expected slot: say where it is
    }
    speed_timeout(now);
    if (auto o = modes_.handle_timeout(now)) {
        finish_mode(std::move(*o), now);
    }
    send_due_modes();
    if (auto o = arming_.handle_timeout(now)) {
        state_done(o->id, o->result, std::move(o->detail));
    }
    send_due_arming();
    if (due.baud) {
        actions_.push_back(SwitchBaud{*due.baud});
    }
    if (due.pulse) {
        actions_.push_back(PulseReset{*due.pulse});
        last_error_ = "autopilot unresponsive, reset pulse " + std::to_string(*due.pulse);
    } else if (due.pulses_exhausted) {
        last_error_ = "autopilot unresponsive; reset pulses exhausted";
    }
    send_gcs_heartbeat_if_due(now);
    if (now >= phase_deadline_) {
        phase_deadline_ = kNever;
        if (phase_ == Phase::WaitBoot) {
            last_error_ = link_.up() ? "autopilot did not finish booting within boot_timeout"
                                     : "no heartbeat from the autopilot within boot_timeout";
            if (link_.up()) {
                if (const auto pulse = link_.take_pulse()) {
                    actions_.push_back(PulseReset{*pulse});
                }
            }
        } else if (retry_pending_) {
            retry_pending_ = false;
            enter(Phase::Params, now);
        }
    }
    flush_rc(now);
}

TimePoint Driver::poll_timeout() const {
    TimePoint t = std::min(
        {missions_.poll_timeout(), params_.poll_timeout(), phase_deadline_, rc_.poll_timeout(),
         next_gcs_heartbeat_ == kNever ? kNever : next_gcs_heartbeat_ + kGcsHeartbeatSlack,
         auto_check_.poll_timeout(), link_.poll_timeout(), modes_.poll_timeout(), arming_.poll_timeout()});
    if (speed_request_) {
        t = std::min(t, speed_request_->deadline);
    }
    return t;
}

std::optional<std::vector<std::uint8_t>> Driver::poll_transmit() {
    auto f = out_.poll_transmit();
    if (f && tap_) {
        tap_(true, *f);
    }
    return f;
}

std::optional<Event> Driver::poll_event() {
    if (events_.empty()) {
        return std::nullopt;
    }
    auto e = std::move(events_.front());
    events_.pop_front();
    return e;
}

std::optional<DriverAction> Driver::poll_action() {
    if (actions_.empty()) {
        return std::nullopt;
    }
    auto a = actions_.front();
    actions_.pop_front();
    return a;
}

void Driver::flush_rc(TimePoint now) {
    rc_.set_enabled(state_ == VehicleState::ManualNavigation && link_.up(), now);
    while (auto m = rc_.poll(now)) {
        out_.send(*m);
    }
}

// --- sequencing --------------------------------------------------------------------------------------------

void Driver::enter(Phase p, TimePoint now) {
    phase_ = p;
    phase_deadline_ = kNever;
    retry_pending_ = false;
    switch (p) {
        case Phase::Closed:
            break;
        case Phase::WaitBoot:
            link_.forget_boot_clock();
            phase_deadline_ = now + config_.boot_timeout;
            break;
        case Phase::Params:
            ++syncs_;
            request_streams();
            sequence_fetch_ = params_.fetch_all(now);
            break;
        case Phase::Mission:
            sequence_download_ = missions_.download(now);
            break;
        case Phase::ApplyParams:
            start_apply_params(now);
            break;
        case Phase::Ready:
            last_error_.clear();
            link_.refill_pulses();
            if (!ready_s_) {
                ready_s_ = seconds_between(sequence_start_, now);  // later READYs (resyncs) keep it
            }
            emit(Ready{seconds_between(sequence_start_, now)});
            break;
    }
    update_state(now, false);
}

void Driver::request_streams() {
    if (!config_.use_message_interval) {
        for (const auto& s : config_.stream_rates) {
            mav::RequestDataStream m;
            m.target_system = config_.target_sysid;
            m.target_component = config_.target_compid;
            m.req_stream_id = static_cast<std::uint8_t>(s.stream);
            m.req_message_rate = static_cast<std::uint16_t>(s.hz);
            m.start_stop = s.hz > 0 ? 1 : 0;
            out_.send(m);
        }
        return;
    }
    for (const auto& r : config_.message_rates) {
        mav::CommandLong m;
        m.target_system = config_.target_sysid;
        m.target_component = config_.target_compid;
        m.command = mavlink::kCmdSetMessageInterval;
        m.param1 = static_cast<float>(r.msgid);
        m.param2 = r.hz > 0 ? static_cast<float>(1e6 / r.hz) : -1.0f;  // -1 disables the message
        out_.send(m);
    }
}

void Driver::start_apply_params(TimePoint now) {
    sequence_sets_.clear();
    apply_failures_.clear();
    for (const auto& p : config_.params) {
        const auto have = params_.cached(p.name);
        if (!have) {
            apply_failures_.push_back(p.name + ": the autopilot has no such parameter");
            continue;
        }
        if (std::fabs(*have - static_cast<float>(p.value)) <= 1e-6f * std::max(1.0f, std::fabs(*have))) {
            continue;
        }
        sequence_sets_[params_.set(p.name, static_cast<float>(p.value), now)] = p.name;
    }
    if (sequence_sets_.empty()) {
        if (apply_failures_.empty()) {
            enter(Phase::Ready, now);
        } else {
            sequence_failed(apply_failures_.front(), now);
        }
    }
}

void Driver::sequence_failed(const std::string& why, TimePoint now) {
    last_error_ = why;
    retry_pending_ = true;
    phase_deadline_ = now + kRetryPause;
}

void Driver::drain_clients(TimePoint now) {
    while (auto s = missions_.poll_stored()) {
        auto it = mission_ops_.find(s->id);
        if (it == mission_ops_.end() || it->second.kind != RequestKind::WriteItems || it->second.id == 0) {
            continue;
        }
        PendingOp& op = it->second;
        for (std::uint16_t slot = std::max(op.first, op.stored_through); slot < s->through; ++slot) {
            const std::size_t i = static_cast<std::size_t>(slot - op.first);
            if (i < op.items.size()) {
                emit(MissionItemStored{slot, op.items[i]});
            }
        }
        op.stored_through = std::max(op.stored_through, s->through);
    }
    while (auto c = missions_.poll_completion()) {
        on_mission_done(std::move(*c), now);
    }
    while (auto c = params_.poll_completion()) {
        on_param_done(std::move(*c), now);
    }
}

void Driver::on_mission_done(MissionCompletion c, TimePoint now) {
    if (c.id == sequence_download_) {
        sequence_download_ = 0;
        if (c.result != MissionResult::Success) {
            if (c.result != MissionResult::Cancelled) {
                sequence_failed("mission download: " + std::string(to_string(c.result)) + " " + c.detail,
                                now);
            }
            return;
        }
        mission_.clear();
        home_slot_.reset();
        for (std::size_t i = 0; i < c.items.size(); ++i) {
            if (i == 0) {
                home_slot_ = c.items[0];
                if (!telemetry_.home) {
                    telemetry_.home = Position{c.items[0].x * 1e-7, c.items[0].y * 1e-7, c.items[0].z};
                }
            } else {
                mission_.push_back(decode_item(c.items[i]));
            }
        }
        if (phase_ == Phase::Mission) {
            enter(Phase::ApplyParams, now);
        }
        return;
    }
    const auto it = mission_ops_.find(c.id);
    if (it == mission_ops_.end()) {
        return;
    }
    PendingOp op = std::move(it->second);
    mission_ops_.erase(it);
    if (retry_with_stops_as_jumps(op, c, now)) {
        return;
    }
    const RequestResult r = from_mission(c.result);
    if (r == RequestResult::Ok) {
        switch (op.kind) {
            case RequestKind::UploadMission:
                mission_ = op.items;
                break;
            case RequestKind::WriteItems:
                for (std::size_t i = 0; i < op.items.size(); ++i) {
                    const std::size_t slot = op.first + i;
                    if (slot >= 1 && slot - 1 < mission_.size()) {
                        mission_[slot - 1] = op.items[i];
                    }
                }
                break;
            case RequestKind::ClearMission:
                mission_.clear();
                restore_board_speed(now);  // no plan any more: the board's own speed again
                break;
            case RequestKind::DownloadMission: {
                mission_.clear();
                for (std::size_t i = 1; i < c.items.size(); ++i) {
                    mission_.push_back(decode_item(c.items[i]));
                }
                RequestDone d{op.id, op.kind, r, {}, mission_, std::nullopt, {}, std::nullopt, std::nullopt};
                emit(std::move(d));
                return;
            }
            default:
                break;
        }
        update_speed(now);  // the item being driven to may have a new speed
    }
    // How this board runs a Stop is known once one was written to it (a 2.x board refuses the first).
    const bool known = stop_as_jump_ || has_stop(op.items);
    done(op.id, op.kind, r, c.detail, known ? std::optional<bool>(stop_as_jump_) : std::nullopt);
}

// A board that does not store NAV_LOITER_UNLIM (APM:Rover 2.x: MAV_MISSION_UNSUPPORTED) gets Stop items as
// jumps past the mission's end from now on (encode_item()), and the same write once more.
bool Driver::retry_with_stops_as_jumps(const PendingOp& op, const MissionCompletion& c, TimePoint now) {
    constexpr std::uint8_t kMissionUnsupported = 3;
    const bool writes = op.kind == RequestKind::UploadMission || op.kind == RequestKind::WriteItems;
    if (!writes || !has_stop(op.items) || stop_as_jump_ || c.result != MissionResult::Denied ||
        c.refusal != kMissionUnsupported) {
        return false;
    }
    stop_as_jump_ = true;
    std::vector<mav::MissionItemInt> wire;
    if (op.kind == RequestKind::UploadMission) {
        wire.push_back(home_slot_ ? *home_slot_ : home_item(telemetry_.home.value_or(Position{})));
    }
    for (const auto& it : op.items) {
        wire.push_back(encode_item(it, true));
    }
    const std::uint32_t again = op.kind == RequestKind::UploadMission
                                    ? missions_.upload(std::move(wire), now)
                                    : missions_.write_partial(op.first, std::move(wire), now);
    mission_ops_[again] = op;
    return true;
}

void Driver::on_param_done(ParamCompletion c, TimePoint now) {
    if (on_speed_param_done(c, now)) {
        return;
    }
    if (c.id == sequence_fetch_) {
        sequence_fetch_ = 0;
        if (c.result == RequestResult::Ok) {
            on_params_known();
            if (phase_ == Phase::Params) {
                enter(Phase::Mission, now);
            }
        } else if (c.result != RequestResult::Cancelled) {
            sequence_failed(c.detail, now);
        }
        return;
    }
    if (const auto it = sequence_sets_.find(c.id); it != sequence_sets_.end()) {
        if (c.result != RequestResult::Ok) {
            apply_failures_.push_back(c.detail.empty() ? it->second + ": " + to_string(c.result) : c.detail);
        }
        sequence_sets_.erase(it);
        if (sequence_sets_.empty() && phase_ == Phase::ApplyParams) {
            if (apply_failures_.empty()) {
                enter(Phase::Ready, now);
            } else {
                sequence_failed("parameter " + apply_failures_.front(), now);
            }
        }
        return;
    }
    const auto it = param_ops_.find(c.id);
    if (it == param_ops_.end()) {
        return;
    }
    RequestDone d{it->second.id, it->second.kind, c.result, c.detail, {}, std::nullopt, {},
                  std::nullopt,  std::nullopt};
    if (c.value) {
        d.param_value = *c.value;
    }
    param_ops_.erase(it);
    emit(std::move(d));
}

void Driver::cancel_everything(const std::string& why, TimePoint now) {
    missions_.cancel_all(why);
    params_.cancel_all(why);
    drain_clients(now);
    sequence_sets_.clear();
    if (auto o = modes_.cancel(why)) {
        finish_mode(std::move(*o), now);
    }
    if (auto o = arming_.cancel(why)) {
        state_done(o->id, o->result, std::move(o->detail));
    }
    override_active_ = false;
}

void Driver::done(std::uint32_t id, RequestKind kind, RequestResult result, std::string detail,
                  std::optional<bool> stop_ends_mission) {
    RequestDone d;
    d.id = id;
    d.kind = kind;
    d.result = result;
    d.detail = std::move(detail);
    d.stop_ends_mission = stop_ends_mission;
    emit(std::move(d));
}

// --- requests ----------------------------------------------------------------------------------------------

std::uint32_t Driver::reject_if_not_ready(RequestKind kind) {
    if (ready()) {
        return 0;
    }
    const std::uint32_t id = next_id_++;
    done(id, kind, RequestResult::NotReady,
         std::string("autopilot not ready (") + to_string(phase_) + (link_.up() ? "" : ", link down") + ")");
    return id;
}

std::uint32_t Driver::upload_mission(std::vector<MissionItem> items, TimePoint now) {
    if (auto id = reject_if_not_ready(RequestKind::UploadMission)) {
        return id;
    }
    std::vector<mav::MissionItemInt> wire;
    wire.reserve(items.size() + 1);
    wire.push_back(home_slot_ ? *home_slot_ : home_item(telemetry_.home.value_or(Position{})));
    for (const auto& it : items) {
        wire.push_back(encode_item(it, stop_as_jump_));
    }
    const std::uint32_t id = next_id_++;
    mission_ops_[missions_.upload(std::move(wire), now)] = {id, RequestKind::UploadMission, std::move(items),
                                                            1};
    drain_clients(now);
    return id;
}

std::uint32_t Driver::write_items(std::uint16_t first_slot, std::vector<MissionItem> items, TimePoint now) {
    if (auto id = reject_if_not_ready(RequestKind::WriteItems)) {
        return id;
    }
    const std::uint32_t id = next_id_++;
    if (first_slot == 0) {
        done(id, RequestKind::WriteItems, RequestResult::Invalid, "slot 0 is home and is not written");
        return id;
    }
    std::vector<mav::MissionItemInt> wire;
    for (const auto& it : items) {
        wire.push_back(encode_item(it, stop_as_jump_));
    }
    mission_ops_[missions_.write_partial(first_slot, std::move(wire), now)] = {id, RequestKind::WriteItems,
                                                                               std::move(items), first_slot};
    drain_clients(now);
    return id;
}

std::uint32_t Driver::download_mission(TimePoint now) {
    if (auto id = reject_if_not_ready(RequestKind::DownloadMission)) {
        return id;
    }
    const std::uint32_t id = next_id_++;
    mission_ops_[missions_.download(now)] = {id, RequestKind::DownloadMission, {}, 0};
    drain_clients(now);
    return id;
}

std::uint32_t Driver::set_current(std::uint16_t slot, TimePoint now) {
    if (auto id = reject_if_not_ready(RequestKind::SetCurrent)) {
        return id;
    }
    const std::uint32_t id = next_id_++;
    auto_check_.retarget(slot);
    current_reached_ = false;  // pointed there on purpose
    mission_ops_[missions_.set_current(slot, now)] = {id, RequestKind::SetCurrent, {}, slot};
    drain_clients(now);
    return id;
}

std::uint32_t Driver::clear_mission(TimePoint now) {
    if (auto id = reject_if_not_ready(RequestKind::ClearMission)) {
        return id;
    }
    const std::uint32_t id = next_id_++;
    mission_ops_[missions_.clear(now)] = {id, RequestKind::ClearMission, {}, 0};
    drain_clients(now);
    return id;
}

std::uint32_t Driver::get_param(const std::string& name, TimePoint now) {
    if (!link_.up()) {
        const std::uint32_t id = next_id_++;
        done(id, RequestKind::GetParam, RequestResult::NotReady, "autopilot link down");
        return id;
    }
    const std::uint32_t id = next_id_++;
    param_ops_[params_.get(name, now)] = {id, RequestKind::GetParam, {}, 0};
    drain_clients(now);
    return id;
}

std::uint32_t Driver::set_param(const std::string& name, double value, TimePoint now) {
    if (auto id = reject_if_not_ready(RequestKind::SetParam)) {
        return id;
    }
    const std::uint32_t id = next_id_++;
    param_ops_[params_.set(name, static_cast<float>(value), now)] = {id, RequestKind::SetParam, {}, 0};
    drain_clients(now);
    return id;
}

void Driver::joystick(double steering, double throttle, TimePoint now) {
    rc_.set_input(steering, throttle, now);
    flush_rc(now);
}

void Driver::operator_reset(TimePoint now) {
    if (failsafe_latched_) {
        failsafe_latched_ = false;
        update_state(now, true);
    }
}

std::uint32_t Driver::request_state(VehicleState target, TimePoint now) {
    const std::uint32_t id = next_id_++;
    // The failsafe needs only a live link; everything else needs a READY autopilot.
    if (!link_.up() || (target != VehicleState::Manual && !ready())) {
        done(id, RequestKind::SetState, RequestResult::NotReady,
             link_.up() ? "autopilot not ready" : "autopilot link down");
        return id;
    }
    if (state_ == VehicleState::ConfigureCheck && target != VehicleState::Manual) {
        // A board that says it is booting (a reboot whose evidence is still coming in, a calibration) will
        // take the mode once it is up: asked again then, never a refusal that ends a plan.
        done(id, RequestKind::SetState, RequestResult::NotReady,
             std::string(to_string(state_)) + " -> " + to_string(target) + ": " +
                 *transition_refusal(state_, target));
        return id;
    }
    if (auto why = transition_refusal(state_, target)) {
        done(id, RequestKind::SetState, RequestResult::Refused,
             std::string(to_string(state_)) + " -> " + to_string(target) + ": " + *why);
        return id;
    }
    const auto mode = static_cast<std::uint32_t>(*mode_for(target));
    const std::string superseded = std::string("superseded by a request for ") + to_string(target);
    if (auto o = modes_.cancel(superseded)) {
        finish_mode(std::move(*o), now);
    }
    if (auto o = arming_.cancel(superseded)) {
        state_done(o->id, o->result, std::move(o->detail));
    }
    if (mode_ && *mode_ == mode) {
        // Same autopilot mode (MANUAL for DIRECTED, MANUAL_NAVIGATION and failsafe MANUAL; AUTO, which may
        // still need arming): only our side changes.
        override_active_ = target == VehicleState::ManualNavigation;
        failsafe_latched_ = failsafe_latched_ || target == VehicleState::Manual;
        update_state(now, true);
        flush_rc(now);
        if (arms_for(target) && needs_arming()) {
            start_arming(id, now);
            return id;
        }
        state_done(id, RequestResult::Ok, {});
        return id;
    }
    // Nothing is running after the cancel above (which words why); an outcome here still gets reported.
    if (auto o = modes_.start(id, target, mode, now)) {
        finish_mode(std::move(*o), now);
    }
    if (target == VehicleState::WaypointNavigation) {
        auto_check_.arm(board_slot(), now);
    }
    send_due_modes();
    return id;
}

void Driver::send_mode(std::uint32_t mode) {
    if (config_.board == Board::Apm2) {
        mav::SetMode m;  // ArduRover 2.x does not know MAV_CMD_DO_SET_MODE
        m.target_system = config_.target_sysid;
        m.base_mode = mavlink::kModeFlagCustomModeEnabled;
        m.custom_mode = mode;
        out_.send(m);
    } else {
        mav::CommandLong m;
        m.target_system = config_.target_sysid;
        m.target_component = config_.target_compid;
        m.command = mavlink::kCmdDoSetMode;
        m.param1 = mavlink::kModeFlagCustomModeEnabled;
        m.param2 = static_cast<float>(mode);
        out_.send(m);
    }
    if (mode == static_cast<std::uint32_t>(RoverMode::Auto) && auto_check_.expected()) {
        // Right behind the mode change, the slot the board is at: a board that restarts its mission on
        // entering AUTO (APM:Rover 2.x) takes it in AUTO and drives on from there instead of heading for item
        // 1 until the AutoEntryCheck sees the restart; to one that does not it is the slot it is already at.
        mav::MissionSetCurrent c;
        c.target_system = config_.target_sysid;
        c.target_component = config_.target_compid;
        c.seq = *auto_check_.expected();
        out_.send(c);
    }
}

void Driver::send_due_modes() {
    while (const auto mode = modes_.poll_send()) {
        send_mode(*mode);
    }
}

void Driver::finish_mode(ModeOutcome o, TimePoint now) {
    if (o.result == RequestResult::Ok) {
        override_active_ = o.target == VehicleState::ManualNavigation;
        failsafe_latched_ = failsafe_latched_ || o.target == VehicleState::Manual;
        update_state(now, true);
        flush_rc(now);
        if (arms_for(o.target) && needs_arming()) {
            start_arming(o.id, now);  // in the new mode: the request is done once the board is armed
            return;
        }
    }
    state_done(o.id, o.result, std::move(o.detail));
}

void Driver::state_done(std::uint32_t id, RequestResult result, std::string detail) {
    RequestDone d;
    d.id = id;
    d.kind = RequestKind::SetState;
    d.result = result;
    d.detail = std::move(detail);
    d.armed = armed();
    emit(std::move(d));
}

// ArduPilot Rover 4.x boots disarmed (ARMING_REQUIRE 1) and drives nothing until armed; a board that needs
// no arming (2.x, ARMING_REQUIRE 0) always reports SAFETY_ARMED. The states in which this system drives the
// vehicle (the mission, the ground joystick) are armed for; DIRECTED is the RC pilot's, who arms with the
// sticks. Arming comes after the mode is confirmed: entering AUTO disarmed skips the position checks
// (Mode::enter()), while arming in AUTO runs them, so a board that could not drive the mission says so now,
// in its own words.
bool Driver::arms_for(VehicleState target) {
    return target == VehicleState::WaypointNavigation || target == VehicleState::ManualNavigation;
}

bool Driver::needs_arming() const {
    return config_.arming == ArmingPolicy::Auto && armed_seen_ && !armed_;
}

void Driver::start_arming(std::uint32_t id, TimePoint now) {
    if (auto o = arming_.start(id, now)) {
        state_done(o->id, o->result, std::move(o->detail));
    }
    send_due_arming();
}

void Driver::send_due_arming() {
    while (arming_.poll_send()) {
        mav::CommandLong m;
        m.target_system = config_.target_sysid;
        m.target_component = config_.target_compid;
        m.command = mavlink::kCmdComponentArmDisarm;
        m.confirmation = static_cast<std::uint8_t>(std::min(arming_.attempt(), 255u));
        m.param1 = 1.0F;  // arm; param2 0: the checks run (21196 would force)
        out_.send(m);
    }
}

void Driver::update_state(TimePoint now, bool requested) {
    VehicleState s = VehicleState::Unknown;
    if (link_.up() && mode_) {
        s = state_for(*mode_, phase_ != Phase::Ready, override_active_, failsafe_latched_);
    }
    const std::string name = mode_ ? rover_mode_name(*mode_) : std::string();
    if (s != state_ || name != mode_name_) {
        ModeChanged e{state_, s, mode_name_, name,
                      requested ? ModeChangeCause::Requested : ModeChangeCause::External};
        state_ = s;
        mode_name_ = name;
        emit(std::move(e));
    }
    telemetry_.state = state_;
    telemetry_.mode = mode_name_;
    telemetry_.custom_mode = mode_;
    if (state_ != VehicleState::ManualNavigation) {
        rc_.set_enabled(false, now);
    }
}

AutopilotStatus Driver::status() const {
    AutopilotStatus s;
    s.link_up = link_.up();
    s.ready = ready();
    s.ready_s = ready_s_;
    s.state = state_;
    s.mode = mode_name_;
    s.position = telemetry_.position;
    s.position_invalid = telemetry_.position_invalid;
    s.mission_current = telemetry_.mission_current;
    s.reboots = reboots_;
    s.link_losses = link_.link_losses();
    s.link_verdicts_deferred = link_.verdicts_deferred();
    s.syncs = syncs_;
    s.reset_pulses = link_.reset_pulses();
    s.armed = armed();
    s.arm_refusals = arming_.refusals();
    s.speed = speed_set_;
    s.mission_items = missions_.answers_int() ? "int" : "float";
    s.auto_restarts_corrected = auto_check_.corrections();
    s.refused_values = refused_values_;
    s.refused_value = refused_value_;
    s.params_cached = params_.table().size();
    s.params_announced = params_.announced();
    s.params_dropped = params_.dropped();
    return s;
}

}  // namespace airseg::autopilot::ardupilot
