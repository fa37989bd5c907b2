#include "services/groundlink/transport/fec_frame.hpp"

#include <algorithm>

#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/crc16.hpp"
#include "services/groundlink/transport/erasure_code.hpp"

namespace airseg::groundlink::fec {
namespace {

constexpr std::uint8_t kShardKind = 0x80;

void emit_shard(std::uint8_t group, std::size_t index, std::size_t n, std::span<const std::uint8_t> bytes,
                std::vector<std::uint8_t>& scratch, std::vector<std::uint8_t>& out) {
    scratch.clear();
    scratch.push_back(static_cast<std::uint8_t>(kShardKind | (group & 0x3FU)));
    scratch.push_back(static_cast<std::uint8_t>(index));
    scratch.push_back(static_cast<std::uint8_t>(n - 1));
    scratch.insert(scratch.end(), bytes.begin(), bytes.end());
    const std::uint16_t crc = crc16_ccitt(scratch);
    scratch.push_back(static_cast<std::uint8_t>(crc & 0xFFU));
    scratch.push_back(static_cast<std::uint8_t>(crc >> 8));
    cobs_encode(scratch, out);
}

}  // namespace

bool is_shard(std::span<const std::uint8_t> plain) {
    return !plain.empty() && (plain[0] & 0xC0U) == kShardKind;
}

void encode_frame(std::span<const std::uint8_t> sealed, std::uint8_t group, std::size_t shard_bytes,
                  std::size_t parity, std::vector<std::uint8_t>& out) {
    const std::size_t n = data_shards_for(sealed.size(), shard_bytes);
    std::vector<std::uint8_t> block(n * shard_bytes, 0);
    block[0] = static_cast<std::uint8_t>(n * shard_bytes - 1 - sealed.size());
    std::copy(sealed.begin(), sealed.end(), block.begin() + 1);
    std::vector<std::span<const std::uint8_t>> data;
    data.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        data.emplace_back(block.data() + i * shard_bytes, shard_bytes);
    }
    std::vector<std::uint8_t> scratch;
    scratch.reserve(shard_bytes + kShardHeaderBytes + kShardCrcBytes);
    for (std::size_t i = 0; i < n; ++i) {
        emit_shard(group, i, n, data[i], scratch, out);
    }
    for (std::size_t j = 0; j < parity && n + j < kMaxShards; ++j) {
        emit_shard(group, n + j, n, encode_parity(data, j), scratch, out);
    }
}

void ShardAssembler::clear() {
    groups_ = {};
}

ShardAssembler::Group& ShardAssembler::slot_for(std::uint8_t id, std::size_t n, std::size_t len,
                                                TimePoint now) {
    for (Group& g : groups_) {
        if (g.used && g.id == id && g.n == n && g.len == len && now - g.last < kStale) {
            return g;
        }
    }
    // A new group: a slot with the same id (an old group, or the same id after the sender restarted), else a
    // free slot, else the oldest one.
    auto* slot =
        std::find_if(groups_.begin(), groups_.end(), [&](const Group& g) { return g.used && g.id == id; });
    if (slot == groups_.end()) {
        slot = std::find_if(groups_.begin(), groups_.end(), [](const Group& g) { return !g.used; });
    }
    if (slot == groups_.end()) {
        slot = std::min_element(groups_.begin(), groups_.end(),
                                [](const Group& a, const Group& b) { return a.order < b.order; });
    }
    *slot = Group{};
    slot->used = true;
    slot->id = id;
    slot->n = n;
    slot->len = len;
    slot->order = next_order_++;
    return *slot;
}

ShardId shard_id(std::span<const std::uint8_t> plain) {
    return ShardId{static_cast<std::uint8_t>(plain[0] & 0x3FU), plain[1]};
}

ShardAssembler::Result ShardAssembler::add(std::span<const std::uint8_t> plain, TimePoint now,
                                           std::vector<std::uint8_t>& frame) {
    if (!is_shard(plain) || plain.size() < kShardHeaderBytes + kShardCrcBytes + 1) {
        return Result::Bad;
    }
    const auto body = plain.first(plain.size() - kShardCrcBytes);
    const auto crc = static_cast<std::uint16_t>(plain[body.size()] | (plain[body.size() + 1] << 8));
    if (crc16_ccitt(body) != crc) {
        return Result::Bad;
    }
    const auto [id, index8] = shard_id(body);
    const std::size_t index = index8;
    const std::size_t n = static_cast<std::size_t>(body[2]) + 1;
    const auto bytes = body.subspan(kShardHeaderBytes);
    if (index >= kMaxShards || n > kMaxShards) {
        return Result::Bad;
    }
    Group& g = slot_for(id, n, bytes.size(), now);
    g.last = now;
    if (g.done || std::find(g.indices.begin(), g.indices.end(), index) != g.indices.end()) {
        return Result::Redundant;
    }
    g.indices.push_back(index);
    g.shards.emplace_back(bytes.begin(), bytes.end());
    if (g.indices.size() < n) {
        return Result::Stored;
    }
    std::vector<Shard> have;
    have.reserve(g.indices.size());
    bool all_data = true;
    for (std::size_t i = 0; i < g.indices.size(); ++i) {
        have.push_back(Shard{g.indices[i], g.shards[i]});
        all_data = all_data && g.indices[i] < n;
    }
    auto data = reconstruct(n, have);
    g.done = true;
    g.indices.clear();
    g.shards.clear();
    if (!data) {
        return Result::Bad;
    }
    ++decoded_;
    if (!all_data) {
        ++repaired_;
    }
    frame.clear();
    for (const auto& d : *data) {
        frame.insert(frame.end(), d.begin(), d.end());
    }
    const std::size_t pad = frame.empty() ? 0 : frame[0];
    if (frame.size() < 1 + pad) {
        return Result::Bad;
    }
    frame.erase(frame.end() - static_cast<std::ptrdiff_t>(pad), frame.end());
    frame.erase(frame.begin());
    return Result::Complete;
}

}  // namespace airseg::groundlink::fec
