// Fuzzes forward error correction of ground-link frames (fec_frame.hpp). The input is split into a frame and
// a damage script. What must hold:
//  - the frame's shards go through lost, flipped and inserted bytes without crashing the assembler, and an
//    undamaged group gives back exactly the frame, once;
//  - raw input bytes fed to the assembler as shards never crash it and never yield a frame longer than a
//    group can carry.
#include <cstdint>
#include <span>
#include <vector>

#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/erasure_code.hpp"
#include "services/groundlink/transport/fec_frame.hpp"
#include "tests/fuzz/require.hpp"

namespace {

using namespace airseg::groundlink;

void raw_shards(std::span<const std::uint8_t> data) {
    fec::ShardAssembler assembler;
    CobsDeframer deframer(1024);
    std::vector<std::uint8_t> out;
    deframer.feed(
        data,
        [&](std::vector<std::uint8_t>&& plain) {
            if (assembler.add(plain, airseg::TimePoint{}, out) == fec::ShardAssembler::Result::Complete) {
                require(out.size() <= fec::kMaxShards * 1024);
            }
        },
        [] {});
}

void damaged_group(std::span<const std::uint8_t> data) {
    if (data.size() < 4) {
        return;
    }
    const std::size_t shard = fec::kMinShardBytes + data[0] % 60;
    const std::size_t parity = data[1] % 40;
    const std::size_t split = 4 + data[2] % (data.size() - 3);
    const auto frame = data.subspan(3, std::min(split, data.size()) - 3);
    const auto script = data.subspan(std::min(split, data.size()));
    if (frame.empty() || fec::data_shards_for(frame.size(), shard) + parity > fec::kMaxShards) {
        return;
    }
    std::vector<std::uint8_t> wire;
    fec::encode_frame(frame, data[0], shard, parity, wire);

    // Each script byte damages the wire at a position it chooses: drop, flip or insert a byte.
    std::vector<std::uint8_t> damaged = wire;
    for (std::size_t i = 0; i + 1 < script.size(); i += 2) {
        if (damaged.empty()) {
            break;
        }
        const std::size_t pos = (script[i] * 131U + i * 7U) % damaged.size();
        switch (script[i + 1] % 3) {
            case 0:
                damaged.erase(damaged.begin() + static_cast<std::ptrdiff_t>(pos));
                break;
            case 1:
                damaged[pos] ^= static_cast<std::uint8_t>(1U << (script[i + 1] % 8));
                break;
            default:
                damaged.insert(damaged.begin() + static_cast<std::ptrdiff_t>(pos), script[i + 1]);
                break;
        }
    }
    fec::ShardAssembler assembler;
    CobsDeframer deframer(4096);
    std::vector<std::uint8_t> out;
    int complete = 0;
    deframer.feed(
        damaged,
        [&](std::vector<std::uint8_t>&& plain) {
            if (assembler.add(plain, airseg::TimePoint{}, out) == fec::ShardAssembler::Result::Complete) {
                ++complete;
                // A CRC-16 can be fooled by a damaged shard; the transport's CRC-32 of the frame catches
                // that. With an undamaged wire the frame must come back exactly.
                if (damaged == wire) {
                    require(std::equal(out.begin(), out.end(), frame.begin(), frame.end()));
                }
            }
        },
        [] {});
    // Damage can fool a shard's CRC-16 (the fuzzer finds such bytes on purpose), and a fooled shard may
    // open a group of its own; the CRC-32 or MAC of the rebuilt frame stops it, above this layer. An
    // undamaged group gives its frame exactly once.
    if (damaged == wire) {
        require(complete == 1);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const std::uint8_t> input(data, size);
    raw_shards(input);
    damaged_group(input);
    return 0;
}
