#include "services/groundlink/protocol/deflate_codec.hpp"

#include <zlib.h>

#include <array>

#include <nlohmann/json.hpp>

namespace airseg::groundlink::protocol {
namespace {

// What results and commands usually look like. DEFLATE refers back into it, so its strings cost a few bits
// instead of their length; the most frequent (the status answer) is last, nearest to the data. Changing it
// changes the wire format: both ends must be built with the same text.
constexpr const char* kDictionaryText =
    R"json([[{"cmd":"status"},{"ok":false,"status":"refused","error":"forbidden bad_request"},{"cmd":"plan.load)json"
    R"json(","plan":{"name":"","elements":[{"type":"waypoint","lat":0.0,"lon":0.0,"speed":1.0}]},"paused":false)json"
    R"json(}],{"ok":true,"result":{"autopilot":{"auto_restarts_corrected":0,"baud":115200,"link":"up","mission_)json"
    R"json(current":0,"mission_items":"float","mode":"MANUAL","position":{"alt":5.0,"lat":41.2756,"lon":1.9866})json"
    R"json(,"ready":true,"ready_s":5.0,"reboots":0,"reconnects":0,"reset_pulses":0,"speed":null,"state":"DIRECT)json"
    R"json(ED"},"groundlink":{"authenticated":false,"bad_messages":0,"commands":0,"commands_refused":0,"crc_err)json"
    R"json(ors":0,"events_dropped":0,"events_sent":0,"frame_payload":1024,"frames_received":2,"frames_sent":19,)json"
    R"json("framing_errors":0,"goodput_bps":0.0,"joystick_inputs":0,"joystick_refused":0,"link":"up","loss":0.0)json"
    R"json(,"mac_failures":0,"mode":"single","oversized":0,"paths":[{"alive":true,"frames_received":2,"frames_s)json"
    R"json(ent":19,"port":"/dev/ttyUSB0"}],"peer_restarts":0,"replays":0,"role":"control (unauthenticated)","rt)json"
    R"json(t_ms":0.0,"rx":{"fast":{"bytes":0,"drops":0,"messages":0,"queue_depth":0,"replaced":0,"retransmissio)json"
    R"json(ns":0},"safe":{"bytes":0,"drops":0,"messages":0,"queue_depth":0,"replaced":0,"retransmissions":0}},")json"
    R"json(telemetry":{"budget_bytes_per_s":1440.0,"delivery_loss":null,"effective_hz":{"link_stats":1.0,"vehic)json"
    R"json(le":2.0},"factor":1.0,"lowerings":0,"requested_hz":{"link_stats":1.0,"vehicle":2.0},"restorations":0)json"
    R"json(,"samples_sent":0,"weak_link":false},"tx":{"fast":{"bytes":0,"drops":0,"messages":0,"queue_depth":0,)json"
    R"json("replaced":0,"retransmissions":0},"safe":{"bytes":0,"drops":0,"messages":0,"queue_depth":0,"replaced)json"
    R"json(":0,"retransmissions":0}},"fec":false,"byte_error_rate":0.0},"plan":{"element":null,"error":null,"in)json"
    R"json(terruption":null,"name":null,"next_waypoint":null,"reaction":null,"state":"none","waypoints_reached")json"
    R"json(:0,"window":0},"services":{"autopilot":{"error":"","health":"up","since":"2026-01-01T00:00:00.000Z"})json"
    R"json(,"flightplan":{"error":"","health":"up","since":"2026-01-01T00:00:00.000Z"},"groundlink":{"error":"")json"
    R"json(,"health":"up","since":"2026-01-01T00:00:00.000Z"},"status":{"error":"","health":"up","since":"2026-)json"
    R"json(01-01T00:00:00.000Z"}},"uptime_s":8.3,"version":"0.1.0"}}])json";

const std::vector<std::uint8_t>& dictionary() {
    static const std::vector<std::uint8_t> bytes = [] {
        std::vector<std::uint8_t> out;
        for (const auto& part : nlohmann::json::parse(kDictionaryText)) {
            const auto cbor = nlohmann::json::to_cbor(part);
            out.insert(out.end(), cbor.begin(), cbor.end());
        }
        return out;
    }();
    return bytes;
}

constexpr int kRawDeflate = -15;  // window bits: no zlib header or checksum (the transport has a CRC)

}  // namespace

std::vector<std::uint8_t> deflate_payload(std::span<const std::uint8_t> data) {
    z_stream z{};
    if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, kRawDeflate, 9, Z_DEFAULT_STRATEGY) != Z_OK) {
        return {};
    }
    const auto& dict = dictionary();
    deflateSetDictionary(&z, dict.data(), static_cast<uInt>(dict.size()));
    std::vector<std::uint8_t> out(deflateBound(&z, static_cast<uLong>(data.size())));
    z.next_in = const_cast<Bytef*>(data.data());  // zlib's API is not const-correct; it does not write here
    z.avail_in = static_cast<uInt>(data.size());
    z.next_out = out.data();
    z.avail_out = static_cast<uInt>(out.size());
    const int rc = deflate(&z, Z_FINISH);
    out.resize(rc == Z_STREAM_END ? z.total_out : 0);
    deflateEnd(&z);
    return out;
}

std::optional<std::vector<std::uint8_t>> inflate_payload(std::span<const std::uint8_t> stream) {
    z_stream z{};
    if (inflateInit2(&z, kRawDeflate) != Z_OK) {
        return std::nullopt;
    }
    const auto& dict = dictionary();
    inflateSetDictionary(&z, dict.data(), static_cast<uInt>(dict.size()));
    z.next_in = const_cast<Bytef*>(stream.data());
    z.avail_in = static_cast<uInt>(stream.size());
    std::vector<std::uint8_t> out;
    std::array<std::uint8_t, 4096> chunk{};
    int rc = Z_OK;
    while (rc == Z_OK) {
        z.next_out = chunk.data();
        z.avail_out = static_cast<uInt>(chunk.size());
        rc = inflate(&z, Z_NO_FLUSH);
        if (rc != Z_OK && rc != Z_STREAM_END) {
            break;
        }
        out.insert(out.end(), chunk.begin(),
                   chunk.begin() + static_cast<std::ptrdiff_t>(chunk.size() - z.avail_out));
        if (out.size() > kMaxInflated) {
            rc = Z_DATA_ERROR;
            break;
        }
        if (rc == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
            rc = Z_BUF_ERROR;  // the stream ended before its last block
        }
    }
    inflateEnd(&z);
    if (rc != Z_STREAM_END || z.avail_in != 0) {
        return std::nullopt;
    }
    return out;
}

}  // namespace airseg::groundlink::protocol
