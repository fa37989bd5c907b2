#include "services/autopilot/ardupilot/arm_control.hpp"

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::autopilot::ardupilot {

namespace {
constexpr std::string_view kArmPrefix = "Arm: ";        // AP_Arming::check_failed() during arm()
constexpr std::string_view kPrearmPrefix = "PreArm: ";  // AP_Arming::update()'s periodic report

bool starts_with(std::string_view text, std::string_view prefix) {
    return text.substr(0, prefix.size()) == prefix;
}

/// The board's words for a person and for JSON: printable ASCII kept, anything else shown as '?'.
std::string printable(std::string_view text) {
    std::string out(text);
    for (char& c : out) {
        if (c < 0x20 || c > 0x7e) {
            c = '?';
        }
    }
    return out;
}
}  // namespace

std::optional<ArmOutcome> ArmControl::start(std::uint32_t id, TimePoint now) {
    auto superseded = cancel("superseded by request " + std::to_string(id));
    request_ = Request{id, Step::Command, 0, now + timeout_, 0};
    arm_texts_.clear();
    send_ = true;
    return superseded;
}

std::optional<ArmOutcome> ArmControl::on_heartbeat(bool armed) {
    if (!request_ || !armed || request_->step == Step::Collect) {
        return std::nullopt;
    }
    return finish(RequestResult::Ok, {});
}

void ArmControl::on_ack(std::uint8_t result, TimePoint now) {
    if (!request_ || request_->step != Step::Command || result == mavlink::kResultInProgress) {
        return;
    }
    if (result == mavlink::kResultAccepted) {
        request_->step = Step::Confirm;  // the heartbeat shows it
        request_->deadline = now + timeout_;
        return;
    }
    request_->step = Step::Collect;
    request_->refused_with = result;
    request_->deadline = now + text_grace_;
}

void ArmControl::on_text(std::string_view text, TimePoint now) {
    if (starts_with(text, kPrearmPrefix)) {
        last_prearm_ = printable(text);
        last_prearm_at_ = now;
    } else if (request_ && starts_with(text, kArmPrefix) && arm_texts_.size() < kMaxTexts) {
        arm_texts_.push_back(printable(text));
    }
}

std::optional<ArmOutcome> ArmControl::cancel(std::string why) {
    if (!request_) {
        return std::nullopt;
    }
    return finish(RequestResult::Cancelled, std::move(why));
}

std::optional<ArmOutcome> ArmControl::handle_timeout(TimePoint now) {
    if (!request_ || now < request_->deadline) {
        return std::nullopt;
    }
    switch (request_->step) {
        case Step::Command:
            if (request_->attempt >= retries_) {
                return finish(RequestResult::Timeout, "no answer to the arm command after " +
                                                          std::to_string(request_->attempt + 1) +
                                                          " attempts");
            }
            ++request_->attempt;
            request_->deadline = now + timeout_;
            send_ = true;
            return std::nullopt;
        case Step::Confirm:
            return finish(RequestResult::Timeout,
                          "the autopilot accepted the arm command but its heartbeat does not show it armed");
        case Step::Collect: {
            ++refusals_;
            last_refusal_ = reason(now);
            return finish(RequestResult::Refused,
                          "the autopilot refused to arm (MAV_RESULT_" +
                              std::string(mavlink::result_name(request_->refused_with)) +
                              "): " + last_refusal_);
        }
    }
    return std::nullopt;
}

std::string ArmControl::reason(TimePoint now) const {
    if (!arm_texts_.empty()) {
        std::string out = arm_texts_.front();
        for (std::size_t i = 1; i < arm_texts_.size(); ++i) {
            out += "; " + arm_texts_[i];
        }
        return out;
    }
    if (!last_prearm_.empty() && now - last_prearm_at_ <= kPrearmFresh) {
        return last_prearm_;
    }
    return "it gave no reason";
}

ArmOutcome ArmControl::finish(RequestResult r, std::string detail) {
    const std::uint32_t id = request_->id;
    request_.reset();
    send_ = false;
    return ArmOutcome{id, r, std::move(detail)};
}

}  // namespace airseg::autopilot::ardupilot
