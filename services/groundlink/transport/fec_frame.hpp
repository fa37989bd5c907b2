#pragma once
// Forward error correction of whole frames (docs/ground-link.md, "Forward error correction"): a sealed
// frame (tag and CRC-32 attached) is cut into n data shards, k parity shards are added (erasure_code.hpp),
// and each shard travels as its own COBS frame with a 3-byte header and a CRC-16. A shard hit by a lost,
// flipped or inserted byte fails its CRC and becomes an erasure; any n good shards give the frame back. So
// the loss unit is a shard of a few dozen bytes instead of the frame, and the frame's own overhead (header,
// frame number, tag, CRC-32) is paid once per group.
//
// Shard: [10gggggg] group id (6 bits), [index] 0..n−1 data, n.. parity, [n − 1], data bytes, CRC-16 (LE).
// The data shards carry [padding count][sealed frame][padding].
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "base/time.hpp"

namespace airseg::groundlink::fec {

inline constexpr std::size_t kShardHeaderBytes = 3;
inline constexpr std::size_t kShardCrcBytes = 2;
/// Wire bytes of a shard besides its data: header, CRC-16, COBS code byte and delimiter.
inline constexpr std::size_t kShardOverhead = kShardHeaderBytes + kShardCrcBytes + 2;
inline constexpr std::size_t kMinShardBytes = 4;
inline constexpr std::size_t kMaxShardBytes = 240;  // one COBS block: no extra code bytes

/// A COBS-decoded frame that is a shard (its first two bits are 10).
[[nodiscard]] bool is_shard(std::span<const std::uint8_t> plain);

/// A shard's group and index, from its header (`plain` holds at least the header: a shard the assembler
/// did not find bad).
struct ShardId {
    std::uint8_t group = 0;
    std::uint8_t index = 0;
};
[[nodiscard]] ShardId shard_id(std::span<const std::uint8_t> plain);

/// Data shards that carry a sealed frame of `frame_bytes` in shards of `shard_bytes`.
[[nodiscard]] constexpr std::size_t data_shards_for(std::size_t frame_bytes, std::size_t shard_bytes) {
    return (frame_bytes + 1 + shard_bytes - 1) / shard_bytes;
}

/// Appends the COBS-encoded, delimited shards (data, then `parity` parity shards) of `sealed` to `out`.
/// Needs data_shards_for(sealed.size(), shard_bytes) + parity <= 255.
void encode_frame(std::span<const std::uint8_t> sealed, std::uint8_t group, std::size_t shard_bytes,
                  std::size_t parity, std::vector<std::uint8_t>& out);

/// Receiver side: collects shards per group and gives back each frame once enough shards arrived.
class ShardAssembler {
  public:
    enum class Result : std::uint8_t {
        Bad,        ///< CRC-16 failed or the header does not parse
        Stored,     ///< a good shard, the group is not complete yet
        Redundant,  ///< a good shard of a group already decoded (or a duplicate index)
        Complete,   ///< the group's frame is in `frame`
    };
    static constexpr std::size_t kGroups = 8;
    /// A group that heard nothing for this long is dropped when its slot is needed.
    static constexpr Duration kStale = std::chrono::seconds(2);

    Result add(std::span<const std::uint8_t> plain, TimePoint now, std::vector<std::uint8_t>& frame);

    std::uint64_t groups_decoded() const { return decoded_; }
    /// Groups that needed parity (some data shard was lost).
    std::uint64_t groups_repaired() const { return repaired_; }
    void clear();

  private:
    struct Group {
        bool used = false;
        bool done = false;
        std::uint8_t id = 0;
        std::size_t n = 0;
        std::size_t len = 0;
        TimePoint last{};
        std::uint64_t order = 0;
        std::vector<std::size_t> indices;
        std::vector<std::vector<std::uint8_t>> shards;
    };
    Group& slot_for(std::uint8_t id, std::size_t n, std::size_t len, TimePoint now);

    std::array<Group, kGroups> groups_{};
    std::uint64_t next_order_ = 0;
    std::uint64_t decoded_ = 0;
    std::uint64_t repaired_ = 0;
};

}  // namespace airseg::groundlink::fec
