#pragma once
// How to frame for a byte error rate p (docs/ground-link.md, "Frame size and forward error correction"):
// plain frames of the goodput-optimal length, or frames cut into shards with parity (fec_frame.hpp) when that
// carries more. A frame of L payload bytes and H overhead arrives with probability (1 − p)^(L+H), so plain
// framing carries L/(L+H)·(1 − p)^(L+H) of the line, best at L = (−H + √(H² + 4H/λ))/2 with λ = −ln(1 − p).
// With shards, the shard data length s is chosen the same way against the shard's own overhead h, and a
// frame of n data shards gets the fewest parity shards k for which n of the n + k shards arrive with
// probability kGroupSuccess; a group that still fails is repaired by the ordinary retransmission.
#include <cstddef>

namespace airseg::groundlink::fec {

inline constexpr double kGroupSuccess = 0.92;
/// Parity is sized for this many times the measured byte error rate.
inline constexpr double kRateMargin = 1.05;
/// Forward error correction is used when it carries at least this much more than plain frames.
inline constexpr double kFecAdvantage = 1.05;

/// The goodput-optimal data length for per-frame overhead `overhead` at byte error rate p (> 0).
[[nodiscard]] double optimal_length(double p, double overhead);

/// Fewest parity shards for which at least n of n + k shards, each arriving with probability `survival`,
/// arrive with probability `success`; 0 when none are needed, and a value past 255 − n when no k suffices.
[[nodiscard]] std::size_t parity_for(std::size_t n, double survival, double success = kGroupSuccess);

/// Probability that a shard of `shard_bytes` data arrives intact at byte error rate p. A shard also dies
/// with the delimiter before it (the two frames merge), and p is an estimate: kRateMargin more is assumed.
[[nodiscard]] double shard_survival(double p, std::size_t shard_bytes);

struct ShardGeometry {
    std::size_t shard_bytes = 0;
    std::size_t data = 0;
    std::size_t parity = 0;
};
/// Shards for a sealed frame of `sealed_bytes` at rate p: shards of `shard_bytes`, or longer ones where the
/// group would need more than 255 shards (a long frame on a bad link).
[[nodiscard]] ShardGeometry fit_frame(std::size_t sealed_bytes, double p, std::size_t shard_bytes);

struct FramePlan {
    bool fec = false;
    std::size_t payload = 0;  ///< chunk bytes per frame
    /// Data bytes per shard (also in a plain plan, for frames far beyond `payload`, such as a segment cut
    /// before the error rate was known); 0 when shards are not allowed.
    std::size_t shard_bytes = 0;
    double shard_survival = 1.0;  ///< probability a shard arrives intact
    double efficiency = 1.0;      ///< expected share of the line that is chunk payload
};

/// The plan for byte error rate p: `frame_overhead` is a plain frame's wire bytes besides its chunks (COBS
/// included), `min_payload`/`max_payload` bound the chunk bytes per frame, `allow_fec` permits shards.
[[nodiscard]] FramePlan plan_frames(double p, std::size_t frame_overhead, std::size_t min_payload,
                                    std::size_t max_payload, bool allow_fec);

}  // namespace airseg::groundlink::fec
