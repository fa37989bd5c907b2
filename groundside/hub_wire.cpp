#include "groundside/hub_wire.hpp"

#include <fmt/format.h>
#include <sodium.h>

#include "base/little_endian.hpp"

namespace airseg::groundside::hub {

namespace {
constexpr std::string_view kProofContext = "airseg-ground hub client v1";
}

std::vector<std::uint8_t> encode(FrameType type, std::span<const std::uint8_t> payload) {
    std::vector<std::uint8_t> out;
    out.reserve(5 + payload.size());
    append_le(out, payload.size() + 1, 4);
    out.push_back(static_cast<std::uint8_t>(type));
    out.insert(out.end(), payload.begin(), payload.end());
    return out;
}

std::vector<std::uint8_t> encode_json(const nlohmann::json& object) {
    const auto text = object.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    return encode(FrameType::Json,
                  std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

bool FrameReader::push(std::span<const std::uint8_t> bytes) {
    if (!error_.empty()) {
        return false;
    }
    buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
    std::size_t at = 0;
    while (buffer_.size() - at >= 4) {
        const auto length = static_cast<std::size_t>(load_le(buffer_.data() + at, 4));
        if (length == 0 || length > kMaxFrame + 1) {
            error_ = fmt::format("bad frame length {} (1..{})", length, kMaxFrame + 1);
            return false;
        }
        if (buffer_.size() - at - 4 < length) {
            break;
        }
        const auto type = buffer_[at + 4];
        if (type != static_cast<std::uint8_t>(FrameType::Json) &&
            type != static_cast<std::uint8_t>(FrameType::Ground)) {
            error_ = fmt::format("unknown frame type {}", type);
            return false;
        }
        frames_.push_back(Frame{static_cast<FrameType>(type),
                                {buffer_.begin() + static_cast<std::ptrdiff_t>(at + 5),
                                 buffer_.begin() + static_cast<std::ptrdiff_t>(at + 4 + length)}});
        at += 4 + length;
    }
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(at));
    return true;
}

std::optional<Frame> FrameReader::next() {
    if (frames_.empty()) {
        return std::nullopt;
    }
    auto frame = std::move(frames_.front());
    frames_.pop_front();
    return frame;
}

std::array<std::uint8_t, kProofBytes> proof(const std::array<std::uint8_t, 32>& key,
                                            std::span<const std::uint8_t> challenge) {
    std::array<std::uint8_t, kProofBytes> out{};
    crypto_generichash_state state;
    crypto_generichash_init(&state, key.data(), key.size(), out.size());
    crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(kProofContext.data()),
                              kProofContext.size());
    crypto_generichash_update(&state, challenge.data(), challenge.size());
    crypto_generichash_final(&state, out.data(), out.size());
    return out;
}

std::string to_hex(std::span<const std::uint8_t> bytes) {
    std::string out(bytes.size() * 2 + 1, '\0');
    sodium_bin2hex(out.data(), out.size(), bytes.data(), bytes.size());
    out.pop_back();
    return out;
}

std::optional<std::vector<std::uint8_t>> from_hex(std::string_view text) {
    if (text.size() % 2 != 0) {
        return std::nullopt;
    }
    std::vector<std::uint8_t> out(text.size() / 2);
    std::size_t written = 0;
    const char* end = nullptr;
    if (sodium_hex2bin(out.data(), out.size(), text.data(), text.size(), nullptr, &written, &end) != 0 ||
        written != out.size() || end != text.data() + text.size()) {
        return std::nullopt;
    }
    return out;
}

}  // namespace airseg::groundside::hub
