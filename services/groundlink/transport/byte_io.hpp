#pragma once
// Explicit little-endian encoding, byte by byte, so the wire format does not depend on the host.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace airseg::groundlink::wire {

inline void put_u8(std::vector<std::uint8_t>& out, std::uint8_t v) {
    out.push_back(v);
}
inline void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
    out.push_back(static_cast<std::uint8_t>(v & 0xFFU));
    out.push_back(static_cast<std::uint8_t>((v >> 8) & 0xFFU));
}
inline void put_u24(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int i = 0; i < 3; ++i) {
        out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU));
    }
}
inline void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) {
        out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU));
    }
}
/// Writes `v` little-endian at `p` (8 bytes).
inline void store_u64(std::uint8_t* p, std::uint64_t v) {
    // Spelt out: compilers merge these into one store on a little-endian host.
    p[0] = static_cast<std::uint8_t>(v);
    p[1] = static_cast<std::uint8_t>(v >> 8);
    p[2] = static_cast<std::uint8_t>(v >> 16);
    p[3] = static_cast<std::uint8_t>(v >> 24);
    p[4] = static_cast<std::uint8_t>(v >> 32);
    p[5] = static_cast<std::uint8_t>(v >> 40);
    p[6] = static_cast<std::uint8_t>(v >> 48);
    p[7] = static_cast<std::uint8_t>(v >> 56);
}
inline void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) {
        out.push_back(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU));
    }
}

/// Bounds-checked reader: every get_* returns false (and leaves the reader failed) instead of reading past
/// the end.
class Reader {
  public:
    explicit Reader(std::span<const std::uint8_t> data) : data_(data) {}

    [[nodiscard]] std::size_t remaining() const { return ok_ ? data_.size() - pos_ : 0; }
    [[nodiscard]] bool ok() const { return ok_; }

    bool get_u8(std::uint8_t& v) { return get_le(v, 1); }
    bool get_u16(std::uint16_t& v) { return get_le(v, 2); }
    bool get_u24(std::uint32_t& v) { return get_le(v, 3); }
    bool get_u64(std::uint64_t& v) { return get_le(v, 8); }
    bool get_bytes(std::size_t n, std::span<const std::uint8_t>& out) {
        if (!ok_ || data_.size() - pos_ < n) {
            ok_ = false;
            return false;
        }
        out = data_.subspan(pos_, n);
        pos_ += n;
        return true;
    }

  private:
    template <typename T>
    bool get_le(T& v, std::size_t n) {
        if (!ok_ || data_.size() - pos_ < n) {
            ok_ = false;
            return false;
        }
        T acc = 0;
        for (std::size_t i = 0; i < n; ++i) {
            acc = static_cast<T>(acc | (static_cast<T>(data_[pos_ + i]) << (8 * i)));
        }
        v = acc;
        pos_ += n;
        return true;
    }

    std::span<const std::uint8_t> data_;
    std::size_t pos_ = 0;
    bool ok_ = true;
};

}  // namespace airseg::groundlink::wire
