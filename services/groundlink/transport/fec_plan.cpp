#include "services/groundlink/transport/fec_plan.hpp"

#include <algorithm>
#include <cmath>

#include "services/groundlink/transport/erasure_code.hpp"
#include "services/groundlink/transport/fec_frame.hpp"

namespace airseg::groundlink::fec {
namespace {

// A group is written at once, and small shards with much parity are several times their frame on the wire:
// past about three of the longest plain frames a group overruns a radio's buffer (2 KiB on a SiK radio)
// while the air is busy with the other end, and every group it overruns is lost.
constexpr std::size_t kGroupWireFrames = 3;

// The sealed frame's bytes besides its chunks: the plain overhead without COBS code byte and delimiter.
std::size_t sealed_overhead(std::size_t frame_overhead) {
    return frame_overhead > 2 ? frame_overhead - 2 : 0;
}

double plain_efficiency(double p, double payload, double overhead) {
    return payload / (payload + overhead) * std::pow(1.0 - p, payload + overhead);
}

}  // namespace

double optimal_length(double p, double overhead) {
    const double lambda = -std::log1p(-p);
    return (-overhead + std::sqrt(overhead * overhead + 4.0 * overhead / lambda)) / 2.0;
}

std::size_t parity_for(std::size_t n, double survival, double success) {
    if (survival >= 1.0) {
        return 0;
    }
    if (survival <= 0.0) {
        return kMaxShards;
    }
    const double ratio = survival / (1.0 - survival);
    // At fewer than n / survival shards the mean falls short of n and the success stays below one half: the
    // search starts just under there.
    const auto from =
        static_cast<std::size_t>(std::max(static_cast<double>(n), static_cast<double>(n) / survival - 2.0));
    for (std::size_t total = from; total <= kMaxShards; ++total) {
        // P(at least n of `total` arrive): the binomial term at n from logarithms (once: boards without an
        // FPU pay dearly for every lgamma), the rest by the ratio of neighbouring terms.
        const auto t = static_cast<double>(total);
        const auto k0 = static_cast<double>(n);
        double term = std::exp(std::lgamma(t + 1) - std::lgamma(k0 + 1) - std::lgamma(t - k0 + 1) +
                               k0 * std::log(survival) + (t - k0) * std::log1p(-survival));
        double p_ok = 0.0;
        for (std::size_t k = n; k <= total; ++k) {
            p_ok += term;
            term *= static_cast<double>(total - k) / static_cast<double>(k + 1) * ratio;
        }
        if (p_ok >= success) {
            return total - n;
        }
    }
    return kMaxShards;
}

double shard_survival(double p, std::size_t shard_bytes) {
    return std::pow(1.0 - p, kRateMargin * (static_cast<double>(shard_bytes + kShardOverhead) + 1.0));
}

ShardGeometry fit_frame(std::size_t sealed_bytes, double p, std::size_t shard_bytes) {
    ShardGeometry g;
    for (g.shard_bytes = shard_bytes; g.shard_bytes <= kMaxShardBytes; ++g.shard_bytes) {
        g.data = data_shards_for(sealed_bytes, g.shard_bytes);
        if (g.data > kMaxShards) {
            continue;
        }
        g.parity = parity_for(g.data, shard_survival(p, g.shard_bytes));
        if (g.data + g.parity <= kMaxShards) {
            return g;
        }
    }
    g.shard_bytes = kMaxShardBytes;
    g.data = data_shards_for(sealed_bytes, g.shard_bytes);
    g.parity = g.data < kMaxShards ? kMaxShards - g.data : 0;
    return g;
}

FramePlan plan_frames(double p, std::size_t frame_overhead, std::size_t min_payload, std::size_t max_payload,
                      bool allow_fec) {
    FramePlan plain;
    if (p <= 0.0) {
        plain.payload = max_payload;
        return plain;
    }
    const auto h = static_cast<double>(frame_overhead);
    plain.payload = static_cast<std::size_t>(
        std::clamp(optimal_length(p, h), static_cast<double>(min_payload), static_cast<double>(max_payload)));
    plain.efficiency = plain_efficiency(p, static_cast<double>(plain.payload), h);
    if (!allow_fec) {
        return plain;
    }

    FramePlan fec;
    fec.fec = true;
    const auto shard_overhead = static_cast<double>(kShardOverhead);
    fec.shard_bytes = static_cast<std::size_t>(std::clamp(std::round(optimal_length(p, shard_overhead)),
                                                          static_cast<double>(kMinShardBytes),
                                                          static_cast<double>(kMaxShardBytes)));
    const auto s = static_cast<double>(fec.shard_bytes);
    fec.shard_survival = shard_survival(p, fec.shard_bytes);
    // The largest frame whose group fits in 255 shards and in kGroupWireFrames of the longest plain frames,
    // within max_payload.
    const std::size_t sealed_extra = sealed_overhead(frame_overhead) + 1;  // + the padding count
    const std::size_t wire_budget = kGroupWireFrames * (max_payload + frame_overhead);
    const auto group_wire = [&](std::size_t shards) { return shards * (fec.shard_bytes + kShardOverhead); };
    std::size_t n = data_shards_for(max_payload + sealed_overhead(frame_overhead), fec.shard_bytes);
    n = std::min(n, kMaxShards);
    std::size_t k = parity_for(n, fec.shard_survival);
    while (n > 1 && (n + k > kMaxShards || group_wire(n + k) > wire_budget)) {
        n = n * 3 / 4;
        k = parity_for(n, fec.shard_survival);
    }
    plain.shard_bytes = fec.shard_bytes;
    plain.shard_survival = fec.shard_survival;
    if (n + k > kMaxShards || group_wire(n + k) > wire_budget ||
        n * fec.shard_bytes <= sealed_extra + min_payload) {
        return plain;
    }
    fec.payload = std::min(max_payload, n * fec.shard_bytes - sealed_extra);
    fec.efficiency = static_cast<double>(fec.payload) / (static_cast<double>(n + k) * (s + shard_overhead)) *
                     kGroupSuccess;
    return fec.efficiency > kFecAdvantage * plain.efficiency ? fec : plain;
}

}  // namespace airseg::groundlink::fec
