#pragma once
// ModeControl: one requested autopilot mode change, from request to exactly one outcome, sans-IO.
//
// start() asks for the mode (poll_send() says to send it); without confirmation within timeout it is sent
// again, `retries` times, then the request ends Timeout. A heartbeat in the mode ends it Ok; a COMMAND_ACK
// refusing MAV_CMD_DO_SET_MODE ends it Refused (ACCEPTED and IN_PROGRESS wait for the heartbeat); cancel()
// ends it Cancelled (superseded by another request, link lost, reboot). One request at a time: start() while
// one is running ends that one Cancelled and returns its outcome, so none is ever dropped.
//
// The frames (SET_MODE or COMMAND_LONG) are the Driver's: it drains poll_send() after start() and
// handle_timeout() and encodes them; it reacts to every returned ModeOutcome.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"

namespace airseg::autopilot::ardupilot {

struct ModeOutcome {
    std::uint32_t id = 0;
    VehicleState target = VehicleState::Unknown;
    std::uint32_t mode = 0;
    RequestResult result = RequestResult::Ok;
    std::string detail;
};

class ModeControl {
  public:
    /// Each attempt waits `timeout` for the heartbeat; `retries` attempts follow the first.
    ModeControl(Duration timeout, unsigned retries) : timeout_(timeout), retries_(retries) {}

    /// Starts request `id` for autopilot mode `mode` (the vehicle state `target`). A request still running
    /// ends Cancelled first and that outcome is returned, so that it is not dropped without one.
    [[nodiscard]] std::optional<ModeOutcome> start(std::uint32_t id, VehicleState target, std::uint32_t mode,
                                                   TimePoint now);
    /// The autopilot reported `custom_mode` in a heartbeat: Ok when it is the mode asked for.
    std::optional<ModeOutcome> on_heartbeat(std::uint32_t custom_mode);
    /// The autopilot answered MAV_CMD_DO_SET_MODE with MAV_RESULT `result`: Refused unless it accepted.
    std::optional<ModeOutcome> on_ack(std::uint8_t result);
    std::optional<ModeOutcome> cancel(std::string why);
    /// Sends the mode again when an attempt is due, or ends the request Timeout when none is left.
    std::optional<ModeOutcome> handle_timeout(TimePoint now);
    TimePoint poll_timeout() const { return request_ ? request_->deadline : kNever; }
    /// The mode to send now (one per attempt).
    std::optional<std::uint32_t> poll_send() { return std::exchange(send_, std::nullopt); }

    bool pending() const { return request_.has_value(); }

  private:
    struct Request {
        std::uint32_t id = 0;
        VehicleState target = VehicleState::Unknown;
        std::uint32_t mode = 0;
        unsigned attempt = 0;
        TimePoint deadline = kNever;
    };
    ModeOutcome finish(RequestResult r, std::string detail);

    Duration timeout_;
    unsigned retries_;
    std::optional<Request> request_;
    std::optional<std::uint32_t> send_;
};

}  // namespace airseg::autopilot::ardupilot
