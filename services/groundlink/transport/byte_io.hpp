#pragma once
// Explicit little-endian encoding, byte by byte, so the wire format does not depend on the host.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "base/little_endian.hpp"

namespace airseg::groundlink::wire {

inline void put_u8(std::vector<std::uint8_t>& out, std::uint8_t v) {
    out.push_back(v);
}
inline void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
    append_le(out, v, 2);
}
inline void put_u24(std::vector<std::uint8_t>& out, std::uint32_t v) {
    append_le(out, v, 3);
}
inline void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    append_le(out, v, 4);
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
    append_le(out, v, 8);
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
        v = static_cast<T>(load_le(data_.data() + pos_, n));
        pos_ += n;
        return true;
    }

    std::span<const std::uint8_t> data_;
    std::size_t pos_ = 0;
    bool ok_ = true;
};

}  // namespace airseg::groundlink::wire
