#pragma once
// A fleet command's MQTT id made the vehicle's request id: a command the broker delivers again after the
// hub restarted (its own memory of answered ids gone), or that the fleet's operator publishes again after a
// lost answer, is answered from the vehicle's record of recent commands and never run twice
// (docs/ground-protocol.md, At most once).
#include <nlohmann/json.hpp>

namespace airseg::ground {

/// `request` with "request_id" taken from the MQTT command's `id` (a string or a number), unless it names
/// its own: "mqtt:" and the id, or "mqtt:#" and the id's 64-bit fingerprint when that would not be a valid
/// request id (over 64 characters, spaces or control characters).
nlohmann::json with_request_id(nlohmann::json request, const nlohmann::json& id);

}  // namespace airseg::ground
