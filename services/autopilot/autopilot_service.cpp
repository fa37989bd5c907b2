#include "services/autopilot/autopilot_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

#include "hal/gpio_pulse.hpp"
#include "services/autopilot/mavlink/target.hpp"

namespace airseg::autopilot {

namespace {
PortKeeperConfig port_config(AutopilotServiceConfig& c) {
    PortKeeperConfig p = c.port;
    if (!c.autopilot.bauds.empty()) {
        p.serial.baud = c.autopilot.bauds.front();
    }
    return p;
}
}  // namespace

AutopilotService::AutopilotService(ServiceContext& ctx, AutopilotServiceConfig config, hal::GpioFactory* gpio)
    : Service("autopilot", ctx),
      config_(std::move(config)),
      gpio_(gpio),
      driver_(config_.autopilot),
      keeper_(strand(), port_config(config_),
              PortKeeper::Handlers{[this] {
                                       if (std::exchange(switching_baud_, false)) {
                                           driver_.on_port_reopened(SteadyClock::now());
                                       } else {
                                           driver_.on_port_open(SteadyClock::now());
                                       }
                                       pump();
                                   },
                                   [this](std::span<const std::uint8_t> bytes) {
                                       driver_.handle_bytes(bytes, SteadyClock::now());
                                       pump();
                                       woke_for_input();
                                   },
                                   [this](const std::string& reason) {
                                       driver_.on_port_closed(reason, SteadyClock::now());
                                       pump();
                                   }}),
      tlog_(config_.tlog),
      gate_(config_.autopilot.target_sysid, config_.autopilot.target_compid),
      uploads_(config_.autopilot.target_sysid, config_.autopilot.target_compid),
      timer_(strand(), ctx.wakes),
      prefix_("autopilot[" + config_.port.serial.path + "]: ") {
    gate_.receive_uploads(uploads_);
    if (config_.gcs_endpoint) {
        endpoint_ = std::make_unique<GcsEndpoint>(
            strand(), *config_.gcs_endpoint,
            [this](std::vector<std::uint8_t> frames) { from_ground_station(frames); });
    }
    if (config_.tlog.enabled || config_.forward_frames || endpoint_) {
        driver_.set_frame_tap([this](bool outgoing, std::span<const std::uint8_t> frame) {
            if (config_.tlog.enabled) {
                tlog_.record(frame, std::chrono::system_clock::now(), SteadyClock::now());
            }
            if (!outgoing && running_) {
                if (addressed_to_airsegd(frame)) {
                    ++to_airsegd_kept_;  // the autopilot's answer to airsegd is no station's business
                    return;
                }
                to_ground_stations(forwarded(frame));
            }
        });
    }
}

AutopilotService::~AutopilotService() = default;

void AutopilotService::on_start() {
    running_ = true;
    calls_.emplace();
    if (config_.reset_line) {
        if (!gpio_) {
            spdlog::warn("{}reset line configured but no GPIO backend; reset pulses disabled", prefix_);
        } else if (auto r = gpio_->request(*config_.reset_line); r.ok()) {
            reset_line_ = r.line;
        } else {
            spdlog::warn("{}reset line: {}; reset pulses disabled", prefix_, r.message);
        }
    }
    auto& bus = ctx_.bus;
    subscriptions_.push_back(
        bus.subscribe<AutopilotRequest>(strand(), [this](const AutopilotRequest& r) { on_request(r); }));
    subscriptions_.push_back(bus.subscribe<JoystickInput>(strand(), [this](const JoystickInput& j) {
        driver_.joystick(j.steering, j.throttle, SteadyClock::now());
        pump();
    }));
    subscriptions_.push_back(bus.subscribe<OperatorReset>(strand(), [this](const OperatorReset&) {
        driver_.operator_reset(SteadyClock::now());
        pump();
    }));
    subscriptions_.push_back(bus.subscribe<GroundStationFrames>(
        strand(), [this](const GroundStationFrames& g) { from_ground_station(g.bytes); }));
    if (endpoint_) {
        if (auto error = endpoint_->start(); !error.empty()) {
            spdlog::error("{}{}; no ground station endpoint", prefix_, error);
        }
    }
    keeper_.start();
    publish_status();
    update_health();
}

void AutopilotService::on_stop() {
    running_ = false;
    calls_.reset();
    subscriptions_.clear();
    timer_.cancel();
    if (endpoint_) {
        endpoint_->stop();
    }
    keeper_.stop();
    tlog_.flush();
}

// Frames a ground station sent the autopilot: mission writes are answered by the gate, the rest written.
void AutopilotService::from_ground_station(std::span<const std::uint8_t> frames) {
    if (!running_) {
        return;
    }
    const auto refused_before = gate_.stats().missions_refused;
    auto out = gate_.from_ground(frames, SteadyClock::now());
    if (gate_.stats().missions_refused != refused_before) {
        log_.log(prefix_ + "refused a mission write from a ground station", SteadyClock::now(),
                 spdlog::level::info,
                 "{}refused a mission write from a ground station ({} so far): missions are flight plans",
                 prefix_, gate_.stats().missions_refused);
    }
    for (const auto& answer : out.to_ground) {
        to_ground_stations(answer);
    }
    drain_uploads();
    if (!keeper_.is_open()) {
        return;
    }
    for (auto& frame : out.to_autopilot) {
        if (config_.tlog.enabled) {
            tlog_.record(frame, std::chrono::system_clock::now(), SteadyClock::now());
        }
        keeper_.write(std::move(frame));
    }
}

bool AutopilotService::addressed_to_airsegd(std::span<const std::uint8_t> frame) const {
    const auto target = mavlink::frame_target(frame);
    return target && target->system == config_.autopilot.own_sysid &&
           target->component == config_.autopilot.own_compid;
}

// The endpoint's ground stations are on the board's network: they get every frame, unthrottled.
void AutopilotService::to_ground_stations(const ForwardedFrame& frame) {
    if (endpoint_) {
        endpoint_->from_vehicle(frame.bytes);
    }
    if (config_.forward_frames) {
        ctx_.bus.publish(frame);
    }
}

void AutopilotService::drain_uploads() {
    for (const auto& answer : uploads_.take_output()) {
        to_ground_stations(answer);
    }
    if (auto m = uploads_.poll_mission(); m && calls_) {
        const auto station = std::to_string(m->sysid) + "/" + std::to_string(m->compid);
        log_.log(prefix_ + "a ground station uploaded a mission", SteadyClock::now(), spdlog::level::info,
                 "{}ground station {} uploaded a mission of {} items: handed to the flight plan manager",
                 prefix_, station, m->items.size());
        GroundStationMissionResult unanswered;
        unanswered.reason = "airseg: no flight plan manager is running";
        ctx_.bus.publish(GroundStationMission{
            station, std::move(m->items),
            Reply<GroundStationMissionResult>(strand(), *calls_, std::move(unanswered),
                                              [this, station](const GroundStationMissionResult& r) {
                                                  if (!r.accepted) {
                                                      log_.log(prefix_ + "a ground station's mission refused",
                                                               SteadyClock::now(), spdlog::level::info,
                                                               "{}ground station {}'s mission refused: {}",
                                                               prefix_, station, r.reason);
                                                  }
                                                  uploads_.answer(r.accepted, r.reason);
                                                  drain_uploads();
                                              })});
    }
    arm_timer();
}

void AutopilotService::on_request(const AutopilotRequest& r) {
    const TimePoint now = SteadyClock::now();
    if (std::holds_alternative<ListParams>(r.op)) {
        // Answered from the cached table: no traffic to the autopilot, so no driver request.
        RequestDone done;
        done.kind = RequestKind::ListParams;
        for (const auto& [name, entry] : driver_.params().table()) {
            done.params.emplace_back(name, static_cast<double>(entry.value));
        }
        if (done.params.empty()) {
            done.result = RequestResult::Refused;
            done.detail = "the parameters have not been downloaded yet (autopilot not ready)";
        }
        r.reply(std::move(done));
        return;
    }
    const std::uint32_t id = std::visit(
        [&](const auto& op) -> std::uint32_t {
            using T = std::decay_t<decltype(op)>;
            if constexpr (std::is_same_v<T, RequestStateChange>) {
                return driver_.request_state(op.state, now);
            } else if constexpr (std::is_same_v<T, UploadMission>) {
                return driver_.upload_mission(op.items, now);
            } else if constexpr (std::is_same_v<T, WriteMissionItems>) {
                return driver_.write_items(op.first_slot, op.items, now);
            } else if constexpr (std::is_same_v<T, DownloadMission>) {
                return driver_.download_mission(now);
            } else if constexpr (std::is_same_v<T, SetMissionCurrent>) {
                return driver_.set_current(op.slot, now);
            } else if constexpr (std::is_same_v<T, ClearMission>) {
                return driver_.clear_mission(now);
            } else if constexpr (std::is_same_v<T, GetParam>) {
                return driver_.get_param(op.name, now);
            } else if constexpr (std::is_same_v<T, ListParams>) {
                return 0;  // answered above
            } else {
                return driver_.set_param(op.name, op.value, now);
            }
        },
        r.op);
    requesters_[id] = r.reply;
    pump();
}

// Everything the driver has for the outside world, then the timer for its next deadline.
void AutopilotService::pump() {
    if (!running_) {
        return;
    }
    while (auto frame = driver_.poll_transmit()) {
        if (keeper_.is_open()) {
            keeper_.write(std::move(*frame));
        }
    }
    bool changed = false;
    while (auto e = driver_.poll_event()) {
        changed = true;
        publish(std::move(*e));
    }
    while (auto a = driver_.poll_action()) {
        if (const auto* p = std::get_if<ardupilot::PulseReset>(&*a)) {
            pulse_reset(p->attempt);
        } else if (const auto* b = std::get_if<ardupilot::SwitchBaud>(&*a)) {
            switch_baud(b->baud);
        }
    }
    if (changed) {
        publish_status();
        update_health();
    } else {
        // Every pump follows an input or a deadline of the driver, which may have moved the telemetry on.
        publish_status_soon(SteadyClock::now());
    }
    arm_timer();
}

void AutopilotService::publish(Event e) {
    std::visit(
        [&](auto& ev) {
            using T = std::decay_t<decltype(ev)>;
            if constexpr (std::is_same_v<T, RequestDone>) {
                if (ev.result != RequestResult::Ok) {
                    log_.log(prefix_ + to_string(ev.kind) + " " + to_string(ev.result), SteadyClock::now(),
                             spdlog::level::info, "{}{} #{}: {} {}", prefix_, to_string(ev.kind), ev.id,
                             to_string(ev.result), ev.detail);
                }
                if (auto it = requesters_.find(ev.id); it != requesters_.end()) {
                    const Reply<RequestDone> reply = std::move(it->second);
                    requesters_.erase(it);
                    reply(std::move(ev));
                }
                return;
            } else if constexpr (std::is_same_v<T, LinkDown>) {
                log_.log(prefix_ + "link down", SteadyClock::now(), spdlog::level::warn, "{}link down: {}",
                         prefix_, ev.reason);
            } else if constexpr (std::is_same_v<T, AutopilotRebooted>) {
                log_.log(prefix_ + "autopilot rebooted", SteadyClock::now(), spdlog::level::warn,
                         "{}autopilot rebooted ({})", prefix_, ev.evidence);
            } else if constexpr (std::is_same_v<T, Ready>) {
                log_.log(prefix_ + "ready", SteadyClock::now(), spdlog::level::info,
                         "{}ready {:.1f} s after the open", prefix_, ev.seconds_from_open);
            } else if constexpr (std::is_same_v<T, ModeChanged>) {
                log_.log(prefix_ + "mode changed", SteadyClock::now(), spdlog::level::info, "{}{} -> {} ({})",
                         prefix_, to_string(ev.from), to_string(ev.to), ev.to_mode);
            }
            ctx_.bus.publish(std::move(ev));
        },
        e);
}

// One timer for the driver's deadlines and the .tlog's flush deadline.
void AutopilotService::arm_timer() {
    timer_.arm(std::min({driver_.poll_timeout(), tlog_.poll_timeout(), uploads_.poll_timeout()}),
               [this] { on_timer(); });
}

// Published from the wake-up that brought the change, so the status costs no wake-up of its own. Inputs
// closer together than status_spacing are published once: a change not yet published goes with the next
// input, or at the latest with the next tick (a second), when the autopilot falls silent.
void AutopilotService::publish_status_soon(TimePoint now) {
    if (now - status_published_at_ >= config_.status_spacing) {
        status_published_at_ = now;
        publish_status();
    }
}

// What changes without an event (the port keeper's retries and errors, the .tlog's counters) is refreshed
// once a second, with every service's tick.
void AutopilotService::on_tick(TimePoint now) {
    log_.flush(now);
    if (running_) {
        publish_status();
        update_health();
    }
}

void AutopilotService::on_timer() {
    if (!running_) {
        return;
    }
    const TimePoint now = SteadyClock::now();
    // A starved daemon reads a backlog of seconds slower than the link's read grace: the heartbeat it is
    // about to judge missing may be in it.
    driver_.handle_timeout(now, keeper_.port().bytes_waiting() > 0);
    tlog_.handle_timeout(now);
    uploads_.handle_timeout(now);
    drain_uploads();
    pump();
}

void AutopilotService::publish_status() {
    AutopilotStatus s = driver_.status();
    s.reconnects = keeper_.reconnects();
    s.baud = keeper_.baud();
    s.tlog_enabled = config_.tlog.enabled;
    s.tlog_write_errors = tlog_.stats().write_errors;
    s.tlog_dropped_frames = tlog_.stats().dropped_frames;
    s.tlog_error = tlog_.stats().last_error;
    s.gcs_missions_too_large = uploads_.refused_too_large();
    s.gcs_to_airsegd_kept = to_airsegd_kept_;
    if (endpoint_) {
        const auto e = endpoint_->stats();
        s.gcs_endpoint = true;
        s.gcs_udp_peers = e.udp_peers;
        s.gcs_tcp_clients = e.tcp_clients;
        s.gcs_udp_peers_evicted = e.udp_peers_evicted;
        s.gcs_tcp_refused = e.tcp_refused;
        s.gcs_frames_in = e.frames_in;
        s.gcs_invalid_in = e.invalid_in;
        s.gcs_dropped_out = e.dropped_out;
    }
    ctx_.bus.publish_latest(s);
    ctx_.bus.publish_latest(driver_.telemetry());
}

void AutopilotService::update_health() {
    if (driver_.ready()) {
        set_health(Health::Up);
    } else if (driver_.link_up()) {
        set_health(Health::Degraded, driver_.last_error().empty()
                                         ? std::string("connecting: ") + ardupilot::to_string(driver_.phase())
                                         : driver_.last_error());
    } else {
        set_health(Health::Down, keeper_.is_open() ? (driver_.last_error().empty() ? "waiting for heartbeats"
                                                                                   : driver_.last_error())
                                                   : keeper_.last_error());
    }
}

// Baud probing: nothing valid came at the current rate. The port is reopened from the strand's queue, not
// from inside pump(): the reopen calls the open handler, which pumps again.
void AutopilotService::switch_baud(unsigned baud) {
    log_.log(prefix_ + "trying another baud rate", SteadyClock::now(), spdlog::level::info,
             "{}no valid frame at {} baud; trying {} baud", prefix_, keeper_.baud(), baud);
    asio::post(strand(), [this, baud] {
        if (!running_) {
            return;
        }
        switching_baud_ = keeper_.is_open();
        keeper_.reopen_at(baud);
        switching_baud_ = false;
    });
}

void AutopilotService::pulse_reset(unsigned attempt) {
    if (!reset_line_) {
        spdlog::warn("{}autopilot unresponsive; no reset line to pulse (attempt {})", prefix_, attempt);
        return;
    }
    spdlog::warn("{}autopilot unresponsive: pulsing {} (attempt {})", prefix_, reset_line_->name(), attempt);
    hal::pulse(strand(), reset_line_, config_.reset_pulse_width, [this](std::error_code ec) {
        if (ec) {
            spdlog::warn("{}reset pulse failed: {}", prefix_, ec.message());
        }
        if (running_) {
            driver_.on_reset_pulsed(SteadyClock::now());
            pump();
        }
    });
}

}  // namespace airseg::autopilot
