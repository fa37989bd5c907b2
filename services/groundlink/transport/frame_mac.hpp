#pragma once
// Frame authentication: keyed BLAKE2b (libsodium crypto_generichash) over a context the wire does not carry
// (both session nonces and the full 64-bit frame number) followed by the frame bytes, truncated to 48 bits.
// Binding the context means a frame of another session, or a frame number from another epoch, fails the
// check.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

inline constexpr std::size_t kMacTagBytes = 6;
using MacTag = std::array<std::uint8_t, kMacTagBytes>;

/// What the sender and receiver both know about a frame besides its bytes.
struct MacContext {
    std::uint64_t sender_nonce = 0;
    std::uint64_t receiver_nonce = 0;
    std::uint64_t frame_number = 0;
};

class FrameMac {
  public:
    explicit FrameMac(const std::array<std::uint8_t, kKeyBytes>& key);
    ~FrameMac();
    FrameMac(const FrameMac&) = delete;
    FrameMac& operator=(const FrameMac&) = delete;

    [[nodiscard]] MacTag tag(const MacContext& ctx, std::span<const std::uint8_t> frame) const;
    /// Constant-time comparison of the expected tag with `received`.
    [[nodiscard]] bool verify(const MacContext& ctx, std::span<const std::uint8_t> frame,
                              std::span<const std::uint8_t> received) const;

  private:
    std::array<std::uint8_t, kKeyBytes> key_;
    // The hash state right after keying (the key block padded and buffered, nothing compressed yet): every
    // tag starts from a copy of it instead of keying again.
    struct KeyedState;
    std::unique_ptr<KeyedState> keyed_;
};

}  // namespace airseg::groundlink
