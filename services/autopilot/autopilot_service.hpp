#pragma once
// AutopilotService: the asio side of the ArduPilot driver. It keeps the autopilot's serial port open
// (PortKeeper: reopen with backoff), feeds the port's bytes and a steady_timer to the sans-IO Driver, writes
// what the driver sends, publishes the driver's events and the autopilot status and telemetry on the bus,
// pulses the reset line when the driver asks, reopens the port at the rate the driver's baud probing asks
// for, and records every frame in the .tlog when enabled (its flush deadline shares the driver's timer).
//
// Bus: subscribes AutopilotRequest (answered through its Reply), JoystickInput, OperatorReset,
// GroundStationFrames (through the GcsGate: mission writes are answered, not written; an upload is received
// and published as a GroundStationMission, answered to the ground station with its Reply); publishes the
// other autopilot::Event types as events, AutopilotStatus and Telemetry as variables, and with forward_frames
// each frame from the autopilot (and the gate's answers) as a ForwardedFrame. A request without a Reply runs
// unanswered. Log prefix: autopilot[<device>]: .
#include <map>
#include <memory>
#include <optional>

#include "hal/gpio.hpp"
#include "services/autopilot/ardupilot/driver.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/autopilot_config.hpp"
#include "services/autopilot/gcs_endpoint.hpp"
#include "services/autopilot/gcs_gate.hpp"
#include "services/autopilot/tlog_writer.hpp"
#include "services/common/deadline_timer.hpp"
#include "services/common/limited_log.hpp"
#include "services/common/port_keeper.hpp"
#include "services/common/service.hpp"

namespace airseg::autopilot {

struct AutopilotServiceConfig {
    AutopilotConfig autopilot;
    PortKeeperConfig port;  // its serial.baud is replaced by autopilot.bauds[0]
    TlogConfig tlog;
    std::optional<hal::GpioLineRequest> reset_line;  // autopilot.reset.line
    Duration reset_pulse_width = milliseconds(200);  // autopilot.reset.pulse_width
    // Status and telemetry are published after each input from the autopilot, at most this often, and at
    // every progress tick (so a change waits at most for the next input or the next tick).
    Duration status_spacing = milliseconds(50);
    /// Publish every frame from the autopilot as a ForwardedFrame (groundlink.mavlink_forward.enabled), for
    /// standard ground stations through the ground link.
    bool forward_frames = false;
    /// autopilot.gcs_endpoint: ground stations on the board's network, straight to the autopilot (through
    /// the same gate), every frame from the autopilot to them; none = off.
    std::optional<GcsEndpointConfig> gcs_endpoint;
};

class AutopilotService : public Service {
  public:
    /// `gpio` may be null when no reset line is configured.
    AutopilotService(ServiceContext& ctx, AutopilotServiceConfig config, hal::GpioFactory* gpio);
    ~AutopilotService() override;

    /// The driver, for tests and the status service; touch only on strand().
    const ardupilot::Driver& driver() const { return driver_; }
    /// The ground station endpoint (autopilot.gcs_endpoint), or null; touch only on strand().
    const GcsEndpoint* gcs_endpoint() const { return endpoint_.get(); }

  protected:
    void on_start() override;
    void on_stop() override;

  private:
    void on_request(const AutopilotRequest& r);
    void pump();
    void arm_timer();
    void on_timer();
    void publish_status();
    void publish_status_soon(TimePoint now);
    void on_tick(TimePoint now) override;
    void publish(Event e);
    void pulse_reset(unsigned attempt);
    void switch_baud(unsigned baud);
    void update_health();
    void from_ground_station(std::span<const std::uint8_t> frames);
    void to_ground_stations(const ForwardedFrame& frame);
    /// A frame of the autopilot's addressed to airsegd itself (its own sysid and compid).
    bool addressed_to_airsegd(std::span<const std::uint8_t> frame) const;
    /// Sends the receiver's answers and hands a complete upload to the flight plan manager.
    void drain_uploads();

    AutopilotServiceConfig config_;
    hal::GpioFactory* gpio_;
    std::shared_ptr<hal::GpioLine> reset_line_;
    ardupilot::Driver driver_;
    PortKeeper keeper_;
    TlogWriter tlog_;
    GcsGate gate_;
    MissionReceiver uploads_;
    std::optional<ReplyGuard> calls_;  // the flight plan manager's verdicts run only while started
    std::unique_ptr<GcsEndpoint> endpoint_;
    DeadlineTimer timer_;
    TimePoint status_published_at_{};
    std::uint64_t to_airsegd_kept_ = 0;  // the autopilot's frames to airsegd, kept from ground stations
    std::map<std::uint32_t, Reply<RequestDone>> requesters_;  // driver id -> who waits for the result
    std::vector<Subscription> subscriptions_;
    bool running_ = false;
    bool switching_baud_ = false;  // the next open is a baud probe's reopen of the same device
    std::string prefix_;
    LimitedLog log_;  // every line the autopilot or a ground station can make us write
};

}  // namespace airseg::autopilot
