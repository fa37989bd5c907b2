#pragma once
// Explicit little-endian encoding of MAVLink scalars, byte by byte, so the result does not depend on the
// host's byte order or alignment rules (ARM, big-endian hosts); on a little-endian host at run time that
// is a plain (unaligned) copy.
#include <bit>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace airseg::mavlink::wire {

template <class T>
concept Scalar = std::is_arithmetic_v<T>;

template <class T>
using UnsignedOf =
    std::conditional_t<sizeof(T) == 1, std::uint8_t,
                       std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                          std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;

/// Writes `value` at `out` (sizeof(T) bytes), least significant byte first.
template <Scalar T>
constexpr void put(std::uint8_t* out, T value) {
    using U = UnsignedOf<T>;
    if (!std::is_constant_evaluated() && std::endian::native == std::endian::little) {
        std::memcpy(out, &value, sizeof(T));
        return;
    }
    const U bits = std::bit_cast<U>(value);
    for (std::size_t i = 0; i < sizeof(T); ++i) {
        out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
    }
}

/// Reads a T stored least significant byte first at `in` (sizeof(T) bytes).
template <Scalar T>
constexpr T get(const std::uint8_t* in) {
    using U = UnsignedOf<T>;
    if (!std::is_constant_evaluated() && std::endian::native == std::endian::little) {
        // One load: the byte loop below is not always merged into one by the compiler (64-bit members).
        T value;
        std::memcpy(&value, in, sizeof(T));
        return value;
    }
    U bits = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) {
        bits = static_cast<U>(bits | (static_cast<U>(in[i]) << (8 * i)));
    }
    return std::bit_cast<T>(bits);
}

}  // namespace airseg::mavlink::wire
