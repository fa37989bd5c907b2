#pragma once
// JSON as airsegctl prints it. Texts from the vehicle may hold bytes that are not UTF-8 (an autopilot's
// STATUSTEXT or parameter names relayed over the radio, whose CBOR does not check them): shown with U+FFFD in
// their place, never an exception (nlohmann's dump throws type_error.316 on them by default).
#include <nlohmann/json.hpp>
#include <string>

namespace airseg::client {

inline std::string dump_text(const nlohmann::json& value, int indent = -1) {
    return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace airseg::client
