#pragma once
// The ground hub's client socket (Unix or TCP): length-prefixed frames, each either a JSON object of the
// hub's own (greeting, hello, welcome, link statistics) or one ground-protocol message exactly as it crosses
// the radio. Layout and the exchange are in docs/ground-station.md.
//   frame = u32 little-endian length of what follows | u8 type | payload
// Sans-IO: bytes in, frames out; shared by airseg-ground and airsegctl.
#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace airseg::groundside::hub {

enum class FrameType : std::uint8_t { Json = 1, Ground = 2 };

/// Bigger than any ground-protocol message and any plan the hub relays; a longer length is a broken peer.
inline constexpr std::size_t kMaxFrame = 1 << 20;
inline constexpr std::size_t kChallengeBytes = 32;
inline constexpr std::size_t kProofBytes = 32;
/// Where airseg-ground listens by default and airsegctl looks for it.
inline constexpr std::string_view kDefaultSocket = "/run/airseg-ground/ground.sock";

struct Frame {
    FrameType type = FrameType::Json;
    std::vector<std::uint8_t> payload;
};

std::vector<std::uint8_t> encode(FrameType type, std::span<const std::uint8_t> payload);
std::vector<std::uint8_t> encode_json(const nlohmann::json& object);

class FrameReader {
  public:
    /// Takes bytes read from the socket; false once the stream is broken (error() says how): the caller
    /// closes the connection, since nothing after a bad length can be framed again.
    bool push(std::span<const std::uint8_t> bytes);
    std::optional<Frame> next();
    const std::string& error() const { return error_; }

  private:
    std::vector<std::uint8_t> buffer_;
    std::deque<Frame> frames_;
    std::string error_;
};

/// The answer to the hub's challenge that proves knowledge of a ground-link key without sending it: keyed
/// BLAKE2b-256 of a fixed context and the challenge.
std::array<std::uint8_t, kProofBytes> proof(const std::array<std::uint8_t, 32>& key,
                                            std::span<const std::uint8_t> challenge);

std::string to_hex(std::span<const std::uint8_t> bytes);
/// Empty optional when `text` is not hexadecimal of an even length.
std::optional<std::vector<std::uint8_t>> from_hex(std::string_view text);

}  // namespace airseg::groundside::hub
