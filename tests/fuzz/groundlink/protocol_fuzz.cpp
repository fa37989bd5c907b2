// Fuzzes the ground protocol decoder (what airsegd accepts from the radio and airsegctl from the vehicle).
// For any bytes: decode either refuses with a message or returns a message; a returned message encodes to
// bytes that decode to the same message again (no state the encoder cannot express, no lossy round trip
// after the first quantization).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

#include "services/groundlink/protocol/ground_protocol.hpp"
#include "tests/fuzz/require.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace airseg::groundlink::protocol;
    const DecodeResult first = decode(std::span<const std::uint8_t>(data, size));
    require(first.message.has_value() != !first.error.empty());
    if (!first.message || std::holds_alternative<Unknown>(*first.message)) {
        return 0;
    }
    const auto bytes = encode(*first.message);
    const DecodeResult second = decode(bytes);
    require(second.message.has_value());
    const auto third = encode(*second.message);
    require(third == bytes);
    return 0;
}
