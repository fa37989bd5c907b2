#pragma once
// ArmControl: arming the autopilot for one request, from the command to exactly one outcome, sans-IO.
//
// start() asks for MAV_CMD_COMPONENT_ARM_DISARM (param1 1, never the force code: poll_send() says when to
// send it); it is sent again after `timeout` without an answer, `retries` times, then the request ends
// Timeout. COMMAND_ACK ACCEPTED is confirmed by a heartbeat with MAV_MODE_FLAG_SAFETY_ARMED (Ok; none within
// `timeout`: Timeout); a heartbeat showing the board armed ends it Ok whatever the acknowledgement. Any other
// result is a refusal: ArduPilot says why in STATUSTEXTs, "Arm: <reason>" for the attempt and "PreArm:
// <reason>" every 30 s while a check fails, and its texts leave through a queue that can put them after
// the acknowledgement, so the refusal waits `text_grace` for them and then ends Refused, its detail the
// "Arm: " texts since the command (or the last "PreArm: " text of the last minute). cancel() ends it
// Cancelled. One request at a time: start() while one runs ends that one Cancelled and returns its outcome.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"

namespace airseg::autopilot::ardupilot {

struct ArmOutcome {
    std::uint32_t id = 0;
    RequestResult result = RequestResult::Ok;
    std::string detail;
};

class ArmControl {
  public:
    static constexpr Duration kDefaultTextGrace = milliseconds(500);
    static constexpr Duration kPrearmFresh = seconds(60);  // a PreArm text this old still says why
    static constexpr std::size_t kMaxTexts = 4;            // "Arm: " texts kept for one attempt

    ArmControl(Duration timeout, unsigned retries, Duration text_grace = kDefaultTextGrace)
        : timeout_(timeout), retries_(retries), text_grace_(text_grace) {}

    [[nodiscard]] std::optional<ArmOutcome> start(std::uint32_t id, TimePoint now);
    /// A heartbeat: `armed` its MAV_MODE_FLAG_SAFETY_ARMED.
    std::optional<ArmOutcome> on_heartbeat(bool armed);
    /// COMMAND_ACK for MAV_CMD_COMPONENT_ARM_DISARM with MAV_RESULT `result`.
    void on_ack(std::uint8_t result, TimePoint now);
    /// Every STATUSTEXT of the autopilot: the arming reasons are kept.
    void on_text(std::string_view text, TimePoint now);
    std::optional<ArmOutcome> cancel(std::string why);
    std::optional<ArmOutcome> handle_timeout(TimePoint now);
    TimePoint poll_timeout() const { return request_ ? request_->deadline : kNever; }
    /// True once per attempt: send the arm command now (its confirmation field: attempt()).
    bool poll_send() { return std::exchange(send_, false); }
    unsigned attempt() const { return request_ ? request_->attempt : 0; }
    bool pending() const { return request_.has_value(); }
    /// Arming attempts the autopilot refused, ever.
    unsigned refusals() const { return refusals_; }
    /// The last refusal's reason ("" before any).
    const std::string& last_refusal() const { return last_refusal_; }

  private:
    enum class Step : std::uint8_t { Command, Confirm, Collect };
    struct Request {
        std::uint32_t id = 0;
        Step step = Step::Command;
        unsigned attempt = 0;
        TimePoint deadline = kNever;
        std::uint8_t refused_with = 0;
    };
    ArmOutcome finish(RequestResult r, std::string detail);
    std::string reason(TimePoint now) const;

    Duration timeout_;
    unsigned retries_;
    Duration text_grace_;
    std::optional<Request> request_;
    bool send_ = false;
    std::vector<std::string> arm_texts_;
    std::string last_prearm_;
    TimePoint last_prearm_at_{};
    unsigned refusals_ = 0;
    std::string last_refusal_;
};

}  // namespace airseg::autopilot::ardupilot
