#include "services/groundlink/transport/error_rate_meter.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace airseg::groundlink {

void ErrorRateMeter::on_frame(std::size_t wire_bytes, bool good) {
    if (wire_bytes == 0) {
        return;
    }
    const std::size_t c = std::min<std::size_t>(std::bit_width(wire_bytes) - 1, kClasses - 1);
    stale_ = true;
    bursty_stale_ = true;
    (good ? classes_[c].good : classes_[c].bad) += 1.0;
    if (last_bad_) {
        after_bad_ += 1.0;
        bad_after_bad_ += good ? 0.0 : 1.0;
    }
    last_bad_ = !good;
    classes_[c].bytes += static_cast<double>(wire_bytes);
    bytes_ += static_cast<double>(wire_bytes);
    frames_ += 1.0;
    if (bytes_ > kWindowBytes) {
        for (auto& k : classes_) {
            k.good /= 2;
            k.bad /= 2;
            k.bytes /= 2;
        }
        bytes_ /= 2;
        frames_ /= 2;
        after_bad_ /= 2;
        bad_after_bad_ /= 2;
        vanished_ /= 2;
    }
}

void ErrorRateMeter::on_vanished(double frames) {
    vanished_ = std::max(0.0, vanished_ + frames);
    bursty_stale_ = true;
}

std::optional<double> ErrorRateMeter::byte_error_rate() const {
    if (stale_) {
        estimate_ = estimate();
        stale_ = false;
    }
    return estimate_;
}

std::optional<double> ErrorRateMeter::estimate() const {
    if (bytes_ < kMinBytes || frames_ < kMinFrames) {
        return std::nullopt;
    }
    double bad = 0.0;
    for (const auto& k : classes_) {
        bad += k.bad;
    }
    if (bad < 0.5) {
        return 0.0;
    }
    // The log-likelihood in u = ln(1 − p) is Σ good·T·u + bad·ln(1 − e^(uT)); its derivative falls as u
    // rises towards 0, so the root is found by bisection.
    auto slope = [&](double u) {
        double d = 0.0;
        for (const auto& k : classes_) {
            const double frames = k.good + k.bad;
            if (frames <= 0.0) {
                continue;
            }
            const double t = k.bytes / frames;
            const double survive = std::exp(u * t);
            d += k.good * t - k.bad * t * survive / std::max(1.0 - survive, 1e-12);
        }
        return d;
    };
    double lo = std::log1p(-kMaxRate);  // slope >= 0 here unless the rate is above the cap
    double hi = std::log1p(-1e-7);
    if (slope(lo) <= 0.0) {
        return kMaxRate;
    }
    for (int i = 0; i < 40; ++i) {  // u to about 1e-13: far below what the rate needs
        const double mid = (lo + hi) / 2;
        (slope(mid) > 0.0 ? lo : hi) = mid;
    }
    return -std::expm1((lo + hi) / 2);
}

}  // namespace airseg::groundlink

namespace airseg::groundlink {

bool ErrorRateMeter::bursty() const {
    if (bursty_stale_) {
        bursty_ = judge_bursty();
        bursty_stale_ = false;
    }
    return bursty_;
}

bool ErrorRateMeter::judge_bursty() const {
    double bad = 0.0;
    for (const auto& k : classes_) {
        bad += k.bad;
    }
    if (vanished_ >= kMinVanished && vanished_ > kVanishedRatio * bad) {
        return true;
    }
    if (after_bad_ < 20.0 || frames_ <= 0.0) {
        return false;
    }
    const double p_bad = bad / frames_;
    return bad_after_bad_ / after_bad_ > kBurstRatio * p_bad;
}

}  // namespace airseg::groundlink
