#pragma once
// Receiver-side estimate of the byte corruption rate (bad frames per byte received, a moving window) and the
// frame payload that maximizes goodput at that rate: with per-frame overhead H and byte error rate p, the
// efficiency L/(L+H)·(1-p)^(L+H) peaks at L = (−H + √(H² + 4H/p)) / 2. The peer reports it to the sender.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace airseg::groundlink {

class CorruptionMeter {
  public:
    static constexpr double kFrameOverhead = 22.0;   // bytes per frame besides payload
    static constexpr double kMinBytes = 4000.0;      // no estimate below this many bytes
    static constexpr double kWindowBytes = 40000.0;  // older history decays by half past this

    void on_bytes(std::size_t n) {
        bytes_ += static_cast<double>(n);
        if (bytes_ > kWindowBytes) {
            bytes_ /= 2;
            bad_ /= 2;
        }
    }
    void on_bad_frame() { bad_ += 1.0; }

    /// Suggested frame payload (bytes), nullopt before enough bytes were seen.
    [[nodiscard]] std::optional<std::size_t> suggested_payload() const {
        if (bytes_ < kMinBytes) {
            return std::nullopt;
        }
        if (bad_ < 0.5) {
            return 0xFFFF;
        }
        const double p = bad_ / bytes_;
        const double h = kFrameOverhead;
        const double l = (-h + std::sqrt(h * h + 4.0 * h / p)) / 2.0;
        return static_cast<std::size_t>(std::clamp(l, 1.0, 65535.0));
    }

  private:
    double bytes_ = 0.0;
    double bad_ = 0.0;
};

}  // namespace airseg::groundlink
