#pragma once
// Frame numbers of one session: the wire carries 24 bits, the receiver reconstructs the full 64-bit number
// nearest to the next expected one (as QUIC does), and a 64-frame sliding window rejects replays and
// duplicates.
#include <cstdint>

#include "services/groundlink/transport/frame.hpp"

namespace airseg::groundlink {

class ReplayWindow {
  public:
    enum class Check : std::uint8_t { Fresh, Duplicate, TooOld };

    [[nodiscard]] std::uint64_t reconstruct(std::uint32_t truncated) const {
        constexpr std::uint64_t kWin = std::uint64_t{1} << 24;
        constexpr std::uint64_t kHalf = kWin / 2;
        const std::uint64_t expected = any_ ? largest_ + 1 : 0;
        std::uint64_t candidate = (expected & ~(kWin - 1)) | (truncated & frame::kFrameNumberMask);
        if (candidate + kHalf <= expected) {
            candidate += kWin;
        } else if (candidate > expected + kHalf && candidate >= kWin) {
            candidate -= kWin;
        }
        return candidate;
    }

    [[nodiscard]] Check check(std::uint64_t n) const {
        if (!any_ || n > largest_) {
            return Check::Fresh;
        }
        const std::uint64_t age = largest_ - n;
        if (age >= 64) {
            return Check::TooOld;
        }
        return ((seen_ >> age) & 1U) != 0 ? Check::Duplicate : Check::Fresh;
    }

    /// Records `n`, which check() reported fresh.
    void accept(std::uint64_t n) {
        if (!any_) {
            any_ = true;
            largest_ = n;
            seen_ = 1;
            return;
        }
        if (n > largest_) {
            const std::uint64_t shift = n - largest_;
            seen_ = shift >= 64 ? 0 : seen_ << shift;
            seen_ |= 1;
            largest_ = n;
        } else {
            seen_ |= std::uint64_t{1} << (largest_ - n);
        }
    }

    void reset() { *this = ReplayWindow{}; }

    /// Frame numbers skipped by `n`, a fresh number: positive when it is beyond the largest by more than
    /// one, -1 when it fills an earlier gap (it came late, by another path).
    [[nodiscard]] std::int64_t skipped_by(std::uint64_t n) const {
        if (!any_) {
            return 0;
        }
        return n > largest_ ? static_cast<std::int64_t>(n - largest_ - 1) : -1;
    }

  private:
    std::uint64_t largest_ = 0;
    std::uint64_t seen_ = 0;  // bit k: largest_ - k was received
    bool any_ = false;
};

}  // namespace airseg::groundlink
