#include "services/autopilot/ardupilot/auto_entry_check.hpp"

namespace airseg::autopilot::ardupilot {

void AutoEntryCheck::arm(std::uint16_t expected, TimePoint now) {
    expected_ = expected;
    in_auto_ = false;
    deadline_ = now + kWindow;
    corrected_at_.reset();
}

void AutoEntryCheck::on_auto(TimePoint now) {
    if (!expected_ || in_auto_) {
        return;
    }
    in_auto_ = true;
    deadline_ = now + kWindow;  // from the entry itself: the request may have taken retries
}

void AutoEntryCheck::retarget(std::uint16_t slot) {
    if (expected_) {
        expected_ = slot;
        corrected_at_.reset();
    }
}

void AutoEntryCheck::on_reached(std::uint16_t seq) {
    if (expected_ && *expected_ == seq) {
        expected_.reset();  // it drove to the expected slot: whatever comes next is progress
    }
}

AutoEntryCheck::Verdict AutoEntryCheck::on_current(std::uint16_t seq, TimePoint now) {
    if (!expected_) {
        return Verdict::Report;
    }
    if (seq == *expected_) {
        if (in_auto_) {
            expected_.reset();  // in AUTO at the expected slot: the entry went right
        }
        return Verdict::Report;
    }
    // Corrected even before the heartbeat confirms AUTO: the board restarts the mission as it switches, and
    // its MISSION_CURRENT may come before the heartbeat that says so.
    if (corrected_at_ && now - *corrected_at_ < kCorrectionGap) {
        return Verdict::Suppress;
    }
    corrected_at_ = now;
    ++corrections_;
    return Verdict::Correct;
}

bool AutoEntryCheck::handle_timeout(TimePoint now) {
    if (!expected_ || now < deadline_) {
        return false;
    }
    expected_.reset();
    return true;
}

}  // namespace airseg::autopilot::ardupilot
