#pragma once
// Consistent Overhead Byte Stuffing: a frame never contains 0x00, so 0x00 delimits frames and the receiver
// resynchronizes at the next delimiter after lost, inserted or corrupted bytes. Overhead: at most one byte
// per 254 (0.4 %), plus the delimiter.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <vector>

namespace airseg::groundlink {

/// Appends the COBS encoding of `data` followed by the 0x00 delimiter to `out`.
void cobs_encode(std::span<const std::uint8_t> data, std::vector<std::uint8_t>& out);
/// Worst-case encoded size (delimiter included) of `n` bytes.
constexpr std::size_t cobs_max_encoded(std::size_t n) {
    return n + n / 254 + 2;
}
/// Decodes one frame body (without delimiter); nullopt when the encoding is invalid.
std::optional<std::vector<std::uint8_t>> cobs_decode(std::span<const std::uint8_t> encoded);

/// Splits a byte stream at 0x00 delimiters into decoded frames. The buffer is bounded: a frame longer than
/// `max_encoded` is discarded up to the next delimiter.
class CobsDeframer {
  public:
    explicit CobsDeframer(std::size_t max_encoded) : max_encoded_(max_encoded) {}

    /// Feeds bytes; calls `on_frame(std::vector<uint8_t>&&)` for each decoded frame and `on_error()` for each
    /// invalid or oversize one.
    template <typename OnFrame, typename OnError>
    void feed(std::span<const std::uint8_t> bytes, OnFrame&& on_frame, OnError&& on_error) {
        const std::uint8_t* p = bytes.data();
        const std::uint8_t* const end = p + bytes.size();
        while (p < end) {
            // Up to the next delimiter in one piece: a read of a long frame has none.
            const auto* zero =
                static_cast<const std::uint8_t*>(std::memchr(p, 0, static_cast<std::size_t>(end - p)));
            const std::uint8_t* stop = zero != nullptr ? zero : end;
            const auto n = static_cast<std::size_t>(stop - p);
            const std::size_t room = max_encoded_ > buf_.size() ? max_encoded_ - buf_.size() : 0;
            buf_.insert(buf_.end(), p, p + std::min(n, room));
            overflow_ = overflow_ || n > room;
            if (zero == nullptr) {
                return;
            }
            p = zero + 1;
            last_encoded_ = buf_.size() + 1;
            if (overflow_) {
                on_error();
            } else if (!buf_.empty()) {
                if (auto frame = cobs_decode(buf_)) {
                    on_frame(std::move(*frame));
                } else {
                    on_error();
                }
            }
            buf_.clear();
            overflow_ = false;
        }
    }
    /// Wire bytes (delimiter included, capped at max_encoded + 1) of the frame last handed to a callback.
    [[nodiscard]] std::size_t last_encoded_bytes() const { return last_encoded_; }

  private:
    std::size_t max_encoded_;
    std::vector<std::uint8_t> buf_;
    bool overflow_ = false;
    std::size_t last_encoded_ = 0;
};

}  // namespace airseg::groundlink
