#pragma once
// Systematic Reed–Solomon erasure code over GF(2^8) (polynomial 0x11D) with a Cauchy generator: n data
// shards and up to 255 − n parity shards of equal length; any n of them give back the data. Parity shard j
// (shard index n + j) is Σ_i c(j, i)·D_i with c(j, i) = 1 / ((n + j) ⊕ i). Every square submatrix of a Cauchy
// matrix is invertible, which is what makes any n shards enough.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace airseg::groundlink::fec {

inline constexpr std::size_t kMaxShards = 255;

/// Parity shard `parity_index` (0-based, shard index n + parity_index) of `data` (n shards, equal length).
std::vector<std::uint8_t> encode_parity(std::span<const std::span<const std::uint8_t>> data,
                                        std::size_t parity_index);

/// One received shard: its index (0..n−1 data, n.. parity) and bytes.
struct Shard {
    std::size_t index = 0;
    std::span<const std::uint8_t> bytes;
};

/// The n data shards back from any n distinct shards (more are ignored). nullopt when fewer than n distinct
/// indices are given, an index is out of range, or the lengths differ.
std::optional<std::vector<std::vector<std::uint8_t>>> reconstruct(std::size_t n,
                                                                  std::span<const Shard> shards);

}  // namespace airseg::groundlink::fec
