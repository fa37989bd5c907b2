#include "services/autopilot/ardupilot/mode_control.hpp"

#include "services/autopilot/ardupilot/rover_modes.hpp"
#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {

namespace {
constexpr std::uint8_t kMavResultAccepted = mavlink::kResultAccepted;
constexpr std::uint8_t kMavResultInProgress = mavlink::kResultInProgress;
}  // namespace

std::optional<ModeOutcome> ModeControl::start(std::uint32_t id, VehicleState target, std::uint32_t mode,
                                              TimePoint now) {
    auto superseded = cancel("superseded by request " + std::to_string(id));
    request_ = Request{id, target, mode, 0, now + timeout_};
    send_ = mode;
    return superseded;
}

std::optional<ModeOutcome> ModeControl::on_heartbeat(std::uint32_t custom_mode) {
    if (!request_ || custom_mode != request_->mode) {
        return std::nullopt;
    }
    return finish(RequestResult::Ok, {});
}

std::optional<ModeOutcome> ModeControl::on_ack(std::uint8_t result) {
    if (!request_ || result == kMavResultAccepted || result == kMavResultInProgress) {
        return std::nullopt;  // accepted / in progress: the heartbeat confirms
    }
    return finish(RequestResult::Refused, std::string("autopilot answered MAV_RESULT_") +
                                              mavlink::result_name(result) + " to mode " +
                                              rover_mode_name(request_->mode));
}

std::optional<ModeOutcome> ModeControl::cancel(std::string why) {
    if (!request_) {
        return std::nullopt;
    }
    return finish(RequestResult::Cancelled, std::move(why));
}

std::optional<ModeOutcome> ModeControl::handle_timeout(TimePoint now) {
    if (!request_ || now < request_->deadline) {
        return std::nullopt;
    }
    if (request_->attempt >= retries_) {
        return finish(RequestResult::Timeout, std::string("no heartbeat in ") +
                                                  rover_mode_name(request_->mode) + " after " +
                                                  std::to_string(request_->attempt + 1) + " attempts");
    }
    ++request_->attempt;
    send_ = request_->mode;
    request_->deadline = now + timeout_;
    return std::nullopt;
}

ModeOutcome ModeControl::finish(RequestResult r, std::string detail) {
    const Request req = *request_;
    request_.reset();
    send_.reset();
    return ModeOutcome{req.id, req.target, req.mode, r, std::move(detail)};
}

}  // namespace airseg::autopilot::ardupilot
