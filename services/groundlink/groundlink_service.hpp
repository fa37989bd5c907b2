#pragma once
// The ground-link service: the transport core on one or two serial radio pairs (or UDP), the ground protocol
// on top, commands from the ground through the shared dispatcher, and link statistics in the status document.
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hal/udp_socket.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/common/deadline_timer.hpp"
#include "services/common/limited_log.hpp"
#include "services/common/port_keeper.hpp"
#include "services/common/service.hpp"
#include "services/common/slack_timer.hpp"
#include "services/flightplan/plan_progress.hpp"
#include "services/groundlink/delivery_meter.hpp"
#include "services/groundlink/event_text.hpp"
#include "services/groundlink/frame_forwarder.hpp"
#include "services/groundlink/link/link_driver.hpp"
#include "services/groundlink/protocol/ground_protocol.hpp"
#include "services/groundlink/telemetry_sample.hpp"
#include "services/groundlink/telemetry_scheduler.hpp"
#include "services/groundlink/transport/radio_profile.hpp"

namespace airseg::groundlink {

struct GroundlinkServiceConfig {
    std::string mode = "single";  // single | split | redundant | udp
    std::vector<std::string> ports{"/dev/ttyUSB0"};
    unsigned baud = 57600;
    Duration reconnect_min = std::chrono::milliseconds(500);
    Duration reconnect_max = std::chrono::seconds(10);
    std::string key_file;  // empty: frames are not authenticated (status says so)
    /// A second key whose holders may watch but not command (empty: none). Needs key_file.
    std::string monitor_key_file;
    /// Without key_file, whether the ground may command the vehicle unauthenticated (groundlink.insecure).
    /// Without either, every command, joystick input and MAVLink frame from the ground is refused.
    bool insecure = false;
    TelemetrySchedulerConfig telemetry;
    hal::UdpConfig udp;
    TransportConfig transport;  // paths, path_mode, link rate, key and boot nonce are set by the service
    /// groundlink.radio: the radios' air, which the transport paces for on serial links (not in mode udp).
    RadioProfile radio;
    Duration stats_interval = std::chrono::seconds(1);
    /// groundlink.mavlink_forward: the autopilot's frames for standard ground stations (ForwardedFrame from
    /// the bus, as MavlinkFrames messages) and theirs back (GroundStationFrames, control key only).
    FrameForwarderConfig mavlink_forward;
};

class GroundlinkService : public Service {
  public:
    GroundlinkService(ServiceContext& ctx, GroundlinkServiceConfig config);
    ~GroundlinkService() override;

  protected:
    void on_start() override;
    void on_stop() override;
    void on_tick(TimePoint now) override;

  private:
    /// The ground end's role, from the key its session was authenticated with: the monitor key (the
    /// transport's second key) may watch, the control key may command. Unkeyed links are control.
    [[nodiscard]] Role ground_role() const {
        if (refusing_unauthenticated()) {
            return Role::Monitor;
        }
        return driver_ && driver_->core().session_key() == 1 ? Role::Monitor : Role::Control;
    }
    /// No key and no explicit groundlink.insecure: anyone on the channel could be the ground station.
    [[nodiscard]] bool refusing_unauthenticated() const { return !control_key_ && !config_.insecure; }
    void make_driver();
    void attach_writers();
    void register_commands();
    void subscribe_bus();
    /// A flight plan drives the autopilot's mission (its rolling window): slot events are the plan's to say.
    bool plan_driving() const;
    void on_message(Delivered message);
    void on_command(const protocol::Command& command);
    void on_joystick(const protocol::Joystick& joystick);
    void on_ground_station_frames(protocol::MavlinkFrames frames);
    void on_forwarded(const autopilot::ForwardedFrame& frame);
    void pump_forward();
    void on_event(const TransportEvent& event);
    void send_event(protocol::Event::Severity severity, std::string text);
    void do_stats();
    void feed_scheduler(TimePoint now);
    void arm_telemetry();
    void on_telemetry_timer();
    void send_link_stats(TimePoint now);
    /// One of airseg's own telemetry messages to the transport, counted for the scheduler.
    void send_own_fast(std::uint8_t priority, std::uint16_t topic, std::span<const std::uint8_t> bytes);
    void update_health();
    void publish_status();
    /// What the telemetry rates report is made of, copied so it can be rendered later on another strand.
    struct RatesSnapshot {
        TelemetryScheduler scheduler;
        std::uint64_t samples_sent = 0;
        std::optional<double> delivery_loss;
    };
    RatesSnapshot rates_snapshot() const { return {scheduler_, samples_sent_, delivery_.loss()}; }
    static nlohmann::json rates_json(const RatesSnapshot& rates);
    nlohmann::json rates_json() const { return rates_json(rates_snapshot()); }

    GroundlinkServiceConfig config_;
    std::unique_ptr<LinkDriver> driver_;
    TransportConfig transport_;
    std::optional<std::array<std::uint8_t, kKeyBytes>> control_key_;
    TelemetryScheduler scheduler_;
    DeliveryMeter delivery_;
    SlackTimer telemetry_timer_;
    FrameForwarder forwarder_;
    DeadlineTimer forward_timer_;
    std::uint64_t forward_refused_ = 0;      // forwarded frames the transport did not take (queue full)
    std::uint64_t from_ground_frames_ = 0;   // MavlinkFrames messages passed to the autopilot
    std::uint64_t from_ground_refused_ = 0;  // ... dropped: forwarding off, or from a monitor key
    std::optional<autopilot::Telemetry> vehicle_;
    PlanProgressSample plan_;
    std::optional<flightplan::PlanProgress> plan_progress_;  // the last, for the plan's own events
    std::optional<AnnouncedPlan> announced_plan_;            // the plan last announced, and its appends
    std::uint64_t events_folded_ = 0;  // slot events and window texts not sent while a plan drives
    std::vector<Subscription> subscriptions_;
    bool commands_registered_ = false;
    std::vector<std::unique_ptr<PortKeeper>> keepers_;
    std::unique_ptr<hal::UdpSocket> udp_;
    SlackTimer stats_timer_;
    std::string fatal_;  // a configuration problem found at start (bad key file): the link stays down
    std::uint64_t last_rx_bytes_ = 0;
    /// airseg's own pushed telemetry (samples, link statistics) since the scheduler was last fed: how many
    /// went to the transport, and how many replaced one of theirs still unsent (the link did not carry the
    /// rate). The forwarder's Fast frames are not counted: a ground station's frames of one id replace each
    /// other by design, under their own budget and below telemetry's priority.
    std::uint64_t own_fast_sent_ = 0;
    std::uint64_t own_fast_replaced_ = 0;
    std::uint64_t samples_sent_ = 0;
    std::uint64_t events_sent_ = 0;
    std::uint64_t events_dropped_ = 0;
    std::uint64_t commands_refused_ = 0;
    std::uint64_t joystick_inputs_ = 0;
    std::uint64_t joystick_refused_ = 0;
    TimePoint last_stats_at_{};
    double goodput_bps_ = 0;
    std::uint64_t commands_ = 0;
    std::uint64_t bad_messages_ = 0;
    std::optional<bool> link_state_published_;
    LimitedLog log_;  // lines the ground (or the radio) can make us write
    LimitedLog requests_log_{LineLimiterConfig{20, seconds(10)}};  // the journal of commands from the ground
};

/// The transport configuration for a service configuration: paths and mode from `mode` and `ports`, the link
/// rate from the baud rate (8N1: baud/10 bytes per second) and, on serial links, the air from `radio`.
TransportConfig transport_config_for(const GroundlinkServiceConfig& config);

}  // namespace airseg::groundlink
