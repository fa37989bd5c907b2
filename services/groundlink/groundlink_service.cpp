#include "services/groundlink/groundlink_service.hpp"

#include <array>

#include "services/groundlink/link_state.hpp"

#include <spdlog/spdlog.h>

#include <random>

#include "services/groundlink/groundlink_messages.hpp"
#include "services/groundlink/link/key_file.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"
#include "services/groundlink/telemetry_sample.hpp"
#include "services/status/status_messages.hpp"

namespace airseg::groundlink {

namespace {
/// How soon a reliable forwarded frame the transport's full queue refused is tried again.
constexpr auto kForwardRetry = std::chrono::milliseconds(100);

constexpr const char* kNoKeyRefusal =
    "this vehicle has no ground-link key (groundlink.key_file) and groundlink.insecure is not set, so every "
    "command from the ground is refused";

std::uint64_t random_nonce() {
    std::random_device rd;
    std::uint64_t v = 0;
    while (v == 0) {
        v = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
    }
    return v;
}

nlohmann::json class_json(const ClassStats& s) {
    return {{"messages", s.messages}, {"bytes", s.bytes},       {"retransmissions", s.retransmissions},
            {"drops", s.drops},       {"replaced", s.replaced}, {"queue_depth", s.queue_depth}};
}

/// What the link is paced for (groundlink.baud and groundlink.radio), in the status document.
nlohmann::json pacing_json(const TransportConfig& t) {
    const auto bytes_per_s = [](double r) { return std::round(r * 10) / 10; };
    return {{"serial_bytes_per_s", bytes_per_s(t.link_rate_bytes_per_s)},
            {"air_bytes_per_s",
             bytes_per_s(t.air_rate_bytes_per_s > 0 ? t.air_rate_bytes_per_s : t.link_rate_bytes_per_s)},
            {"air_packet", t.air_packet_payload},
            {"air_packet_overhead", t.air_packet_overhead},
            {"turnaround_ms", std::chrono::duration<double, std::milli>(t.air_turnaround).count()},
            {"duplex", t.half_duplex ? "half" : "full"},
            {"radio_buffer", t.radio_buffer_bytes},
            {"carried_bytes_per_s", bytes_per_s(t.carried_rate_bytes_per_s())}};
}

}  // namespace

TransportConfig transport_config_for(const GroundlinkServiceConfig& config) {
    TransportConfig t = config.transport;
    if (config.mode == "udp") {
        t.paths = 1;
        t.path_mode = PathMode::Single;
        t.half_duplex = false;
    } else {
        t.link_rate_bytes_per_s = config.baud / 10.0;
        config.radio.apply(t, t.link_rate_bytes_per_s);
        t.paths = config.ports.size();
        t.path_mode = config.mode == "split"       ? PathMode::Split
                      : config.mode == "redundant" ? PathMode::Redundant
                                                   : PathMode::Single;
    }
    return t;
}

GroundlinkService::GroundlinkService(ServiceContext& ctx, GroundlinkServiceConfig config)
    : Service("groundlink", ctx),
      config_(std::move(config)),
      scheduler_(config_.telemetry, transport_config_for(config_).carried_rate_bytes_per_s(),
                 SteadyClock::now()),
      telemetry_timer_(strand(), ctx.wakes),
      forwarder_(config_.mavlink_forward, transport_config_for(config_).carried_rate_bytes_per_s(),
                 SteadyClock::now()),
      forward_timer_(strand(), ctx.wakes),
      stats_timer_(strand(), ctx.wakes) {}

GroundlinkService::~GroundlinkService() = default;

void GroundlinkService::on_start() {
    register_commands();
    subscribe_bus();
    transport_ = transport_config_for(config_);
    transport_.boot_nonce = random_nonce();
    auto fail = [this](std::string why) {
        // Running unauthenticated when a key was asked for would be worse than not running the link.
        fatal_ = std::move(why);
        spdlog::error("groundlink: {}; the ground link stays down", fatal_);
        update_health();
        publish_status();
    };
    if (!config_.key_file.empty()) {
        auto key = read_key_file(config_.key_file);
        if (!key.key) {
            return fail(key.error);
        }
        control_key_ = key.key;
        transport_.key = key.key;
    } else if (config_.insecure) {
        spdlog::warn(
            "groundlink: groundlink.insecure is set and there is no key_file: frames are not authenticated, "
            "and anyone on the radio channel (or network) may command this vehicle");
    } else {
        spdlog::warn("groundlink: {}", kNoKeyRefusal);
    }
    if (!config_.monitor_key_file.empty()) {
        if (!control_key_) {
            return fail("groundlink.monitor_key_file needs groundlink.key_file (the control key)");
        }
        auto key = read_key_file(config_.monitor_key_file);
        if (!key.key) {
            return fail(key.error);
        }
        if (*key.key == *control_key_) {
            return fail("groundlink.monitor_key_file holds the same key as groundlink.key_file");
        }
        transport_.second_key = key.key;
    }
    if (auto problems = transport_.validate(); !problems.empty()) {
        return fail(problems.front());
    }
    make_driver();
    if (config_.mode == "udp") {
        udp_ = std::make_unique<hal::UdpSocket>(strand());
        auto r = udp_->open(config_.udp);
        if (!r.ok()) {
            fatal_ = r.message;
            spdlog::error("groundlink[udp]: {}", r.message);
        } else {
            udp_->start_receiving(
                [this](std::span<const std::uint8_t> d, const hal::UdpSocket::Endpoint&) {
                    driver_->handle_bytes(0, d);
                    woke_for_input();
                },
                [this](std::error_code, const std::string& what) {
                    log_.log("groundlink[udp]: receive error", SteadyClock::now(), spdlog::level::warn,
                             "groundlink[udp]: {}", what);
                });
            attach_writers();
        }
    } else {
        for (std::size_t i = 0; i < config_.ports.size(); ++i) {
            PortKeeperConfig pc;
            pc.serial.path = config_.ports[i];
            pc.serial.baud = config_.baud;
            pc.reconnect_min = config_.reconnect_min;
            pc.reconnect_max = config_.reconnect_max;
            keepers_.push_back(
                std::make_unique<PortKeeper>(strand(), pc,
                                             PortKeeper::Handlers{[this] {
                                                                      attach_writers();
                                                                      update_health();
                                                                  },
                                                                  [this, i](std::span<const std::uint8_t> b) {
                                                                      driver_->handle_bytes(i, b);
                                                                      woke_for_input();
                                                                  },
                                                                  [this, i](const std::string&) {
                                                                      driver_->set_writer(i, {});
                                                                      update_health();
                                                                  }}));
        }
        for (auto& k : keepers_) {
            k->start();
        }
    }
    last_stats_at_ = SteadyClock::now();
    update_health();
    do_stats();
    arm_telemetry();
}

void GroundlinkService::make_driver() {
    if (driver_) {
        driver_->stop();
    }
    driver_ =
        std::make_unique<LinkDriver>(strand(), transport_,
                                     LinkDriver::Handlers{[this](Delivered m) { on_message(std::move(m)); },
                                                          [this](const TransportEvent& e) { on_event(e); }},
                                     ctx_.wakes);
    last_rx_bytes_ = 0;
    delivery_.reset();
    own_fast_sent_ = own_fast_replaced_ = 0;
}

void GroundlinkService::attach_writers() {
    if (udp_ && udp_->is_open()) {
        driver_->set_writer(0, [this](std::vector<std::uint8_t> frame) {
            return udp_->send(std::move(frame)) == hal::WriteResult::Queued;
        });
    }
    for (std::size_t i = 0; i < keepers_.size(); ++i) {
        if (keepers_[i]->is_open()) {
            driver_->set_writer(i, [this, i](std::vector<std::uint8_t> frame) {
                return keepers_[i]->write(std::move(frame)) == hal::WriteResult::Queued;
            });
        }
    }
}

void GroundlinkService::on_stop() {
    stats_timer_.cancel();
    telemetry_timer_.cancel();
    forward_timer_.cancel();
    subscriptions_.clear();
    if (driver_) {
        driver_->stop();
    }
    for (auto& k : keepers_) {
        k->stop();
    }
    if (udp_) {
        udp_->close();
    }
}

void GroundlinkService::on_tick(TimePoint now) {
    log_.flush(now);
    requests_log_.flush(now);
}

void GroundlinkService::on_message(Delivered message) {
    auto decoded = protocol::decode(message.bytes);
    if (!decoded.message) {
        ++bad_messages_;
        log_.log("groundlink: dropped a ground message", SteadyClock::now(), spdlog::level::warn,
                 "groundlink: dropped a ground message: {}", decoded.error);
        return;
    }
    if (auto* command = std::get_if<protocol::Command>(&*decoded.message)) {
        on_command(*command);
    } else if (auto* joystick = std::get_if<protocol::Joystick>(&*decoded.message)) {
        on_joystick(*joystick);
    } else if (auto* frames = std::get_if<protocol::MavlinkFrames>(&*decoded.message)) {
        on_ground_station_frames(std::move(*frames));
    } else if (auto* report = std::get_if<protocol::ReceptionReport>(&*decoded.message)) {
        // A message needs about half a round trip to arrive; the margin covers the radios' buffering.
        const auto lag = std::chrono::duration_cast<Duration>(
            std::chrono::duration<double, std::milli>(driver_->stats().srtt_ms / 2 + 250));
        delivery_.on_report(report->received, SteadyClock::now(), lag);
    }
    // Other types from the ground are not expected; unknown types are skipped by design.
}

void GroundlinkService::on_command(const protocol::Command& command) {
    ++commands_;
    // The status document counts a command before its answer leaves, not at the next statistics tick: a
    // client that has its answer and then reads the status sees its command there (a snapshot of plain
    // values; commands come at most as fast as the radio carries them).
    publish_status();
    const std::uint32_t id = command.request_id;
    // A ground hub relays its monitor clients' commands with "role": "monitor": the vehicle runs them with
    // the lesser of the two rights, never more than the link's key grants.
    auto request = command.request;
    bool lowered = false;
    if (request.is_object()) {
        if (auto asked = request.find("role"); asked != request.end()) {
            lowered = *asked == "monitor";
            request.erase(asked);
        }
    }
    const Role role = lowered ? Role::Monitor : ground_role();
    // The journal keeps what the ground asked of the vehicle; a plan upload is cut to its first characters.
    constexpr std::size_t kShown = 160;
    auto shown = command.request.dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
    if (shown.size() > kShown) {
        shown = shown.substr(0, kShown) + fmt::format("… ({} bytes)", shown.size());
    }
    requests_log_.log("groundlink: request from the ground", SteadyClock::now(), spdlog::level::info,
                      "groundlink: request {} from the ground ({}): {}", id, to_string(role), shown);
    ctx_.commands.dispatch(request, role, [this, id, lowered](CommandResult result) {
        asio::dispatch(strand(), [this, id, lowered, result = std::move(result)]() mutable {
            if (result.status == CommandStatus::Forbidden && refusing_unauthenticated()) {
                ++commands_refused_;
                result.error = std::string("not authorised: ") + kNoKeyRefusal;
                log_.log("groundlink: refused a command: no key", SteadyClock::now(), spdlog::level::warn,
                         "groundlink: refused a command from the ground: {}", kNoKeyRefusal);
            } else if (result.status == CommandStatus::Forbidden) {
                ++commands_refused_;
                result.error += lowered
                                    ? " (a monitor client of the ground hub; commands need its control role)"
                                    : " (this ground station uses the monitor key; commands need the control "
                                      "key)";
                log_.log("groundlink: refused a command from a monitor", SteadyClock::now(),
                         spdlog::level::warn, "groundlink: refused a command from a monitor: {}",
                         result.error);
            }
            if (!driver_) {
                return;
            }
            const auto bytes = protocol::encode(protocol::Result{id, result.to_json()});
            const auto r = driver_->send_safe(protocol::kPriorityControl, bytes);
            if (r != SendResult::Accepted) {
                log_.log("groundlink: could not queue an answer", SteadyClock::now(), spdlog::level::warn,
                         "groundlink: could not queue the answer to request {}", id);
            }
        });
    });
}

void GroundlinkService::on_joystick(const protocol::Joystick& joystick) {
    if (ground_role() != Role::Control) {
        if (joystick_refused_++ == 0) {
            spdlog::warn("groundlink: joystick input refused ({})",
                         refusing_unauthenticated() ? "no ground-link key on the vehicle" : "monitor key");
        }
        return;
    }
    ++joystick_inputs_;
    ctx_.bus.publish(autopilot::JoystickInput{joystick.steering, joystick.throttle});
}

void GroundlinkService::on_ground_station_frames(protocol::MavlinkFrames frames) {
    if (!config_.mavlink_forward.enabled || ground_role() != Role::Control) {
        if (from_ground_refused_++ == 0) {
            spdlog::warn("groundlink: MAVLink frames from the ground dropped ({})",
                         !config_.mavlink_forward.enabled ? "groundlink.mavlink_forward is off"
                         : refusing_unauthenticated()     ? "no ground-link key on the vehicle"
                                                          : "monitor key");
        }
        return;
    }
    ++from_ground_frames_;
    ctx_.bus.publish(autopilot::GroundStationFrames{std::move(frames.bytes)});
}

void GroundlinkService::on_forwarded(const autopilot::ForwardedFrame& frame) {
    const bool up = driver_ && driver_->link_up();
    if (!up && frame.delivery != autopilot::ForwardedFrame::Delivery::Reliable) {
        return;  // as with telemetry: nobody listens, and a frame kept now would be stale
    }
    // Reliable frames (a parameter download's values, command and mission answers) wait through an outage:
    // a ground station asked for them once and will not ask again for most.
    const auto dropped_before = forwarder_.stats().dropped;
    const auto now = SteadyClock::now();
    forwarder_.offer(frame, now);
    if (forwarder_.stats().dropped != dropped_before) {
        log_.log("groundlink: forwarded frames overflow", now, spdlog::level::warn,
                 "groundlink: a reliable MAVLink frame (message {}) dropped: {} bytes already wait for the "
                 "ground (groundlink.mavlink_forward.dropped)",
                 frame.id, forwarder_.config().reliable_queue_bytes);
    }
    if (up) {
        pump_forward();
    }
}

// Everything the forwarder lets go now, then its timer for the next. Nothing while the link is down: the
// reliable frames wait in the forwarder (bounded), not in the transport.
void GroundlinkService::pump_forward() {
    const TimePoint now = SteadyClock::now();
    if (!driver_ || !driver_->link_up()) {
        forward_timer_.cancel();
        return;
    }
    bool transport_full = false;
    driver_->batch([&] {
        while (auto out = forwarder_.poll(now)) {
            const bool reliable = out->delivery == autopilot::ForwardedFrame::Delivery::Reliable;
            const auto bytes = protocol::encode(protocol::MavlinkFrames{out->bytes});
            const auto r = reliable ? driver_->send_safe(protocol::kPriorityBulk, bytes)
                                    : driver_->send_fast(protocol::kPriorityBulk,
                                                         protocol::mavlink_topic(out->id), bytes);
            if (r == SendResult::QueueFull && reliable) {
                // The transport's own queue is full: the frame waits here, first, and is tried again shortly.
                forwarder_.put_back(std::move(*out));
                transport_full = true;
                break;
            }
            if (r == SendResult::QueueFull || r == SendResult::TooLarge || r == SendResult::BadPriority) {
                ++forward_refused_;
            }
        }
    });
    const auto next = transport_full ? now + kForwardRetry : forwarder_.poll_timeout();
    forward_timer_.arm(next, [this] { pump_forward(); });
}

void GroundlinkService::on_event(const TransportEvent& event) {
    switch (event.kind) {
        case TransportEvent::Kind::LinkUp:
            log_.log("groundlink: link up", SteadyClock::now(), spdlog::level::info,
                     "groundlink: link up ({})",
                     refusing_unauthenticated()       ? "no key: commands refused"
                     : !control_key_                  ? "unauthenticated: groundlink.insecure"
                     : ground_role() == Role::Control ? "control key"
                                                      : "monitor key");
            pump_forward();  // what waited through the outage
            break;
        case TransportEvent::Kind::LinkDown:
            log_.log("groundlink: link down", SteadyClock::now(), spdlog::level::warn,
                     "groundlink: link down");
            forwarder_.link_down();
            break;
        case TransportEvent::Kind::PeerRestarted:
            log_.log("groundlink: the ground end restarted", SteadyClock::now(), spdlog::level::info,
                     "groundlink: the ground end restarted; session resynchronised");
            delivery_.reset();
            break;
        case TransportEvent::Kind::SessionEstablished:
            delivery_.reset();
            break;
        case TransportEvent::Kind::PathUp:
            log_.log("groundlink: path up", SteadyClock::now(), spdlog::level::info, "groundlink: path {} up",
                     event.path);
            break;
        case TransportEvent::Kind::PathDown:
            log_.log("groundlink: path silent", SteadyClock::now(), spdlog::level::warn,
                     "groundlink: path {} silent", event.path);
            break;
        default:
            break;
    }
    update_health();
    publish_status();  // the status document shows a link change at once, not at the next statistics tick
}

void GroundlinkService::send_event(protocol::Event::Severity severity, std::string text) {
    if (!driver_ || !driver_->link_up()) {
        return;  // events are for the operator watching now; a down link does not queue history
    }
    if (text.size() > protocol::kMaxEventText) {
        text.resize(protocol::kMaxEventText);
    }
    const auto r =
        driver_->send_safe(protocol::kPriorityStatus, protocol::encode(protocol::Event{severity, text}));
    if (r == SendResult::Accepted) {
        ++events_sent_;
    } else {
        ++events_dropped_;
    }
}

void GroundlinkService::do_stats() {
    const TimePoint now = SteadyClock::now();
    if (driver_) {
        const auto& s = driver_->stats();
        const auto rx = s.rx_safe.bytes + s.rx_fast.bytes;
        const double dt = std::chrono::duration<double>(now - last_stats_at_).count();
        if (dt > 0) {
            goodput_bps_ = static_cast<double>(rx - last_rx_bytes_) / dt;
        }
        last_rx_bytes_ = rx;
        last_stats_at_ = now;
        feed_scheduler(now);
    }
    update_health();
    publish_status();
    // On the grid the services' progress ticks use, and up to half a period late to share a wake-up
    // (time.hpp, wake_sharing.hpp).
    stats_timer_.arm(next_on_grid(now, config_.stats_interval), config_.stats_interval / 2,
                     [this] { do_stats(); });
}

void GroundlinkService::feed_scheduler(TimePoint now) {
    const auto& s = driver_->stats();
    LinkQuality q;
    q.up = driver_->link_up();
    // What the ground says it received is the direct measure; the transport's Safe loss estimate stands in
    // until the ground has reported enough (a ground end that does not report, or a slow rate).
    q.loss = delivery_.loss().value_or(s.frame_loss);
    q.replaced_share = own_fast_sent_ > 0
                           ? static_cast<double>(own_fast_replaced_) / static_cast<double>(own_fast_sent_)
                           : 0.0;
    q.link_rate_bytes_per_s = transport_.carried_rate_bytes_per_s();
    own_fast_sent_ = own_fast_replaced_ = 0;
    scheduler_.update_link(q, now);
    arm_telemetry();
}

void GroundlinkService::arm_telemetry() {
    telemetry_timer_.arm(scheduler_.poll_timeout(), scheduler_.poll_slack(),
                         [this] { on_telemetry_timer(); });
}

void GroundlinkService::on_telemetry_timer() {
    const TimePoint now = SteadyClock::now();
    const auto send_due = [&] {
        while (auto kind = scheduler_.poll_due(now)) {
            if (!driver_ || !driver_->link_up()) {
                continue;  // nobody listens: a sample queued now would only be stale when the link comes back
            }
            if (*kind == TelemetryKind::Vehicle && vehicle_) {
                send_own_fast(protocol::kPriorityTelemetry, protocol::kTopicTelemetry,
                              protocol::encode(make_sample(*vehicle_, plan_)));
                ++samples_sent_;
                delivery_.on_pushed(now);
            } else if (*kind == TelemetryKind::LinkStats) {
                send_link_stats(now);
            }
        }
    };
    if (driver_) {
        driver_->batch(send_due);  // the kinds due together go out in one frame
    } else {
        send_due();
    }
    arm_telemetry();
}

void GroundlinkService::send_link_stats(TimePoint now) {
    const auto& s = driver_->stats();
    protocol::LinkStatsReport report;
    report.rtt_ms = static_cast<std::uint16_t>(std::min(65535.0, s.srtt_ms));
    report.loss_permille = static_cast<std::uint16_t>(std::min(1000.0, s.frame_loss * 1000));
    report.goodput_bps = static_cast<std::uint32_t>(goodput_bps_);
    report.retransmissions = static_cast<std::uint32_t>(s.tx_safe.retransmissions);
    report.mac_failures = static_cast<std::uint32_t>(s.mac_failures);
    send_own_fast(protocol::kPriorityStatus, protocol::kTopicLinkStats, protocol::encode(report));
    delivery_.on_pushed(now);
}

void GroundlinkService::send_own_fast(std::uint8_t priority, std::uint16_t topic,
                                      std::span<const std::uint8_t> bytes) {
    const auto r = driver_->send_fast(priority, topic, bytes);
    ++own_fast_sent_;
    if (r == SendResult::Replaced) {
        ++own_fast_replaced_;
    }
}

void GroundlinkService::update_health() {
    if (!fatal_.empty()) {
        set_health(Health::Down, fatal_);
        return;
    }
    std::size_t open = 0;
    std::string missing;
    for (const auto& k : keepers_) {
        if (k->is_open()) {
            ++open;
        } else {
            missing +=
                (missing.empty() ? "" : ", ") + (k->last_error().empty() ? "opening" : k->last_error());
        }
    }
    if (udp_ && udp_->is_open()) {
        ++open;
    }
    if (open == 0) {
        set_health(Health::Down, missing.empty() ? "no port open" : missing);
    } else if (!driver_ || !driver_->link_up()) {
        set_health(Health::Degraded, missing.empty() ? "no ground station heard" : missing);
    } else if (!missing.empty()) {
        set_health(Health::Degraded, missing);
    } else if (refusing_unauthenticated()) {
        set_health(Health::Degraded, "no ground-link key: commands refused");
    } else {
        set_health(Health::Up);
    }
}

void GroundlinkService::publish_status() {
    const bool up = driver_ && driver_->link_up();
    if (!link_state_published_ || *link_state_published_ != up) {
        link_state_published_ = up;
        ctx_.bus.publish_latest(LinkState{up});
    }
    if (!driver_) {
        nlohmann::json g;
        g["mode"] = config_.mode;
        g["link"] = "down";
        g["error"] = fatal_;
        ctx_.bus.publish(status::StatusSection{"groundlink", std::move(g), {}});
        return;
    }
    // Published every second and read when somebody asks for the status document: a snapshot of plain
    // values now, the JSON (about 100,000 instructions) only then.
    const auto& stats = driver_->stats();
    std::vector<std::string> ports;
    for (std::size_t i = 0; i < driver_->core().config().paths; ++i) {
        ports.push_back(config_.mode == "udp" ? "udp" : config_.ports[i]);
    }
    status::StatusSection section{"groundlink", {}, {}};
    section.render =
        [mode = config_.mode, up, s = stats, goodput = goodput_bps_, ports = std::move(ports),
         counters = std::array{commands_, commands_refused_, joystick_inputs_, joystick_refused_,
                               events_sent_, events_dropped_, bad_messages_, events_folded_},
         role = std::string(refusing_unauthenticated() ? "monitor (no key on the vehicle: commands refused)"
                            : !stats.authenticated     ? "control (unauthenticated, groundlink.insecure)"
                                                       : to_string(ground_role())),
         refusal = std::string(refusing_unauthenticated() ? kNoKeyRefusal : ""), rates = rates_snapshot(),
         fwd = forwarder_.stats(), fwd_enabled = config_.mavlink_forward.enabled,
         fwd_budget = forwarder_.budget_bytes_per_s(),
         fwd_counters = std::array{forward_refused_, from_ground_frames_, from_ground_refused_},
         pacing = pacing_json(transport_)] {
            nlohmann::json g;
            g["mode"] = mode;
            g["link"] = up ? "up" : "down";
            g["authenticated"] = s.authenticated;
            g["rtt_ms"] = std::round(s.srtt_ms);
            g["loss"] = std::round(s.frame_loss * 1000) / 1000;
            g["goodput_bps"] = std::round(goodput);
            g["frame_payload"] = s.frame_payload;
            g["pacing"] = pacing;
            // What the link's own traffic says the air carries, beside what it is configured to carry.
            g["pacing"]["measured"] = {
                {"adapt", s.air_adapt},
                {"carried_bytes_per_s", std::round(s.air_carried * 10) / 10},
                {"delivered_bytes_per_s", std::round(s.air_delivered * 10) / 10},
                {"turnaround_ms", s.air_turnaround_ms < 0
                                      ? nlohmann::json(nullptr)
                                      : nlohmann::json(std::round(s.air_turnaround_ms * 10) / 10)},
                {"base_rtt_ms", std::round(s.base_rtt_ms)},
                {"overflows", s.air_overflows}};
            auto rate = [](double r) {
                return r < 0 ? nlohmann::json(nullptr) : nlohmann::json(std::round(r * 1e6) / 1e6);
            };
            g["byte_error_rate"] = rate(s.byte_error_rate);
            g["peer_byte_error_rate"] = rate(s.peer_byte_error_rate);
            g["fec"] = {{"active", s.fec},
                        {"shard_bytes", s.fec_shard_bytes},
                        {"frames_sent", s.fec_frames_sent},
                        {"frames_decoded", s.fec_frames_decoded},
                        {"frames_repaired", s.fec_frames_repaired},
                        {"shard_errors", s.fec_shard_errors}};
            g["frames_sent"] = s.frames_sent;
            g["frames_received"] = s.frames_received;
            g["crc_errors"] = s.crc_errors;
            g["framing_errors"] = s.framing_errors;
            g["mac_failures"] = s.mac_failures;
            g["replays"] = s.replays;
            g["oversized"] = s.oversized;
            g["peer_restarts"] = s.peer_restarts;
            g["commands"] = counters[0];
            g["commands_refused"] = counters[1];
            g["role"] = role;
            if (!refusal.empty()) {
                g["commands_refused_because"] = refusal;
            }
            g["joystick_inputs"] = counters[2];
            g["joystick_refused"] = counters[3];
            g["events_sent"] = counters[4];
            g["events_dropped"] = counters[5];
            g["events_folded"] = counters[7];
            g["bad_messages"] = counters[6];
            g["telemetry"] = rates_json(rates);
            g["mavlink_forward"] = {{"enabled", fwd_enabled},
                                    {"budget_bytes_per_s", std::round(fwd_budget)},
                                    {"offered", fwd.offered},
                                    {"forwarded", fwd.forwarded},
                                    {"forwarded_bytes", fwd.forwarded_bytes},
                                    {"replaced", fwd.replaced},
                                    {"filtered", fwd.filtered},
                                    {"dropped", fwd.dropped + fwd_counters[0]},
                                    {"overflow", fwd.dropped},
                                    {"stale", fwd.stale},
                                    {"reliable_queued", fwd.reliable_queued},
                                    {"reliable_queued_bytes", fwd.reliable_queued_bytes},
                                    {"from_ground", fwd_counters[1]},
                                    {"from_ground_refused", fwd_counters[2]}};
            auto& by_id = g["mavlink_forward"]["freshest_by_id"] = nlohmann::json::object();
            for (const auto& [id, c] : fwd.freshest_by_id) {
                by_id[std::to_string(id)] = {
                    {"offered", c.offered},
                    {"forwarded", c.forwarded},
                    {"replaced", c.replaced},
                    {"stale", c.stale},
                    {"longest_gap_s",
                     std::round(std::chrono::duration<double>(c.longest_gap).count() * 100) / 100}};
            }
            g["tx"] = {{"safe", class_json(s.tx_safe)}, {"fast", class_json(s.tx_fast)}};
            g["rx"] = {{"safe", class_json(s.rx_safe)}, {"fast", class_json(s.rx_fast)}};
            auto& paths = g["paths"] = nlohmann::json::array();
            for (std::size_t i = 0; i < ports.size(); ++i) {
                const auto& p = s.path[i];
                paths.push_back({{"port", ports[i]},
                                 {"alive", p.alive},
                                 {"frames_sent", p.frames_sent},
                                 {"frames_received", p.frames_received}});
            }
            return g;
        };
    ctx_.bus.publish(std::move(section));
}

}  // namespace airseg::groundlink
