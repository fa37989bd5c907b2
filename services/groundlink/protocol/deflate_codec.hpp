#pragma once
// Compression of the ground protocol's command and result payloads (CBOR) with raw DEFLATE (zlib) and a
// preset dictionary both ends share: a typical status document and the keys of the common commands. The
// status answer, about 1.5 KB of CBOR, then takes a few hundred bytes, which is what a weak radio link needs
// (docs/ground-protocol.md, "Compressed command and result").
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace airseg::groundlink::protocol {

/// Largest payload inflate() gives back: a bigger one is refused rather than allocated.
inline constexpr std::size_t kMaxInflated = 256 * 1024;

/// The DEFLATE stream of `data` with the shared dictionary.
std::vector<std::uint8_t> deflate_payload(std::span<const std::uint8_t> data);

/// The payload back; nullopt when the stream is damaged, incomplete or inflates beyond kMaxInflated.
std::optional<std::vector<std::uint8_t>> inflate_payload(std::span<const std::uint8_t> stream);

}  // namespace airseg::groundlink::protocol
