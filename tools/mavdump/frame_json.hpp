#pragma once
// MAVLink frames to JSON lines and back, the format of airseg-mavdump:
//   {"name":"HEARTBEAT","msgid":0,"sysid":1,"compid":1,"seq":7,"v":2,"fields":{"type":10,...}}
// Field names are the specification's, in declaration order; char[] fields are strings (up to the first
// NUL) whose bytes 0x80-0xFF are written \u0080-\u00FF and read back as single bytes, other arrays JSON
// arrays; float NaN and infinities are the strings "nan", "inf", "-inf".
// Every message of ArduPilot's dialect (message_table.hpp, find_dialect_message) is decoded field by field; a
// message id outside it comes out as {"name":"UNKNOWN_<id>",...,"payload":"<hex>"}.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::mavdump {

/// One JSON line (without the newline) for `frame`; tlog records add "timestamp_us" first.
std::string frame_to_json(const mavlink::Frame& frame,
                          std::optional<std::uint64_t> timestamp_us = std::nullopt);

/// One JSON line describing a message of the dialect table, for tools that generate or check traffic:
///   {"name":"MISSION_COUNT","msgid":44,"crc_extra":221,"min_length":4,"length":9,"typed":true,
///    "fields":[{"name":"target_system","type":"uint8_t"},...,{"name":"opaque_id","type":"uint32_t",
///    "extension":true}]}
/// Fields in declaration order; arrays add "length"; "typed": the daemon decodes it (messages.def).
std::string message_to_json(const mavlink::MessageInfo& message);

/// Turns JSON lines back into frames. Keys: "name" or "msgid" (required; both must agree when given),
/// "v" (1 or 2, default 2), "sysid" (default 255), "compid" (default 190), "seq" (default: the next number of
/// that sysid/compid, starting at 0), "fields" (missing fields are 0, except HEARTBEAT's mavlink_version: 3).
/// Unknown ids need "payload" (hex) and "crc_extra". Other keys, such as "timestamp_us", are ignored so that
/// decoder output can be fed back. A line is one JSON document (nlohmann::json), nested at most 32 levels
/// deep; a malformed one is refused with the byte offset of the fault.
class JsonFrameEncoder {
  public:
    struct Result {
        std::vector<std::uint8_t> frame;  // empty on error
        std::string error;                // what was wrong, naming the key or field
    };
    Result encode_line(std::string_view line);

  private:
    std::map<std::pair<std::uint8_t, std::uint8_t>, std::uint8_t> next_seq_;
};

}  // namespace airseg::mavdump
