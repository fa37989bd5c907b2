#include "services/groundlink/transport/frame_mac.hpp"

#include <sodium.h>

#include <stdexcept>

#include "services/groundlink/transport/byte_io.hpp"

namespace airseg::groundlink {

struct FrameMac::KeyedState {
    crypto_generichash_state state;
};

FrameMac::FrameMac(const std::array<std::uint8_t, kKeyBytes>& key) : key_(key) {
    if (sodium_init() < 0) {
        throw std::runtime_error("groundlink: libsodium failed to initialise");
    }
    keyed_ = std::make_unique<KeyedState>();
    crypto_generichash_init(&keyed_->state, key_.data(), key_.size(), crypto_generichash_BYTES_MIN);
}

FrameMac::~FrameMac() {
    sodium_memzero(key_.data(), key_.size());
    sodium_memzero(&keyed_->state, sizeof(keyed_->state));
}

MacTag FrameMac::tag(const MacContext& ctx, std::span<const std::uint8_t> frame) const {
    std::array<std::uint8_t, 24> prefix{};
    wire::store_u64(prefix.data(), ctx.sender_nonce);
    wire::store_u64(prefix.data() + 8, ctx.receiver_nonce);
    wire::store_u64(prefix.data() + 16, ctx.frame_number);

    crypto_generichash_state st = keyed_->state;
    std::array<std::uint8_t, crypto_generichash_BYTES_MIN> full{};
    crypto_generichash_update(&st, prefix.data(), prefix.size());
    crypto_generichash_update(&st, frame.data(), frame.size());
    crypto_generichash_final(&st, full.data(), full.size());
    MacTag out{};
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = full[i];
    }
    return out;
}

bool FrameMac::verify(const MacContext& ctx, std::span<const std::uint8_t> frame,
                      std::span<const std::uint8_t> received) const {
    if (received.size() != kMacTagBytes) {
        return false;
    }
    const MacTag expected = tag(ctx, frame);
    return sodium_memcmp(expected.data(), received.data(), kMacTagBytes) == 0;
}

}  // namespace airseg::groundlink
