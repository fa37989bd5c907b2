#include "services/groundlink/protocol/ground_protocol.hpp"

#include "services/groundlink/protocol/deflate_codec.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "base/little_endian.hpp"

namespace airseg::groundlink::protocol {
namespace {

class Writer {
  public:
    void u8(std::uint64_t v) { out.push_back(static_cast<std::uint8_t>(v & 0xff)); }
    void le(std::uint64_t v, int bytes) { append_le(out, v, static_cast<std::size_t>(bytes)); }
    void bytes(std::span<const std::uint8_t> b) { out.insert(out.end(), b.begin(), b.end()); }
    std::vector<std::uint8_t> out;
};

class Reader {
  public:
    explicit Reader(std::span<const std::uint8_t> b) : b_(b) {}
    bool has(std::size_t n) const { return pos_ + n <= b_.size(); }
    std::uint64_t le(int bytes) {
        const auto n = static_cast<std::size_t>(bytes);
        const std::uint64_t v = load_le(b_.data() + pos_, n);
        pos_ += n;
        return v;
    }
    std::int64_t sle(int bytes) {
        const auto v = le(bytes);
        const auto sign = std::uint64_t{1} << (8 * bytes - 1);
        return static_cast<std::int64_t>((v ^ sign)) - static_cast<std::int64_t>(sign);
    }
    std::span<const std::uint8_t> rest() {
        auto r = b_.subspan(pos_);
        pos_ = b_.size();
        return r;
    }

  private:
    std::span<const std::uint8_t> b_;
    std::size_t pos_ = 0;
};

template <class T>
T clamp_round(double v, double lo, double hi) {
    if (!std::isfinite(v)) {
        return T{};
    }
    return static_cast<T>(std::llround(std::clamp(v, lo, hi)));
}

std::uint64_t twos(std::int64_t v, int bytes) {
    return static_cast<std::uint64_t>(v) & ((bytes == 8) ? ~0ull : ((std::uint64_t{1} << (8 * bytes)) - 1));
}

/// Walks CBOR item headers without recursion and refuses nesting deeper than `max_depth`, so that a hostile
/// payload cannot exhaust the stack of the recursive JSON parser that follows.
bool cbor_nesting_ok(std::span<const std::uint8_t> b, std::size_t max_depth) {
    std::vector<std::uint64_t> remaining;  // items left in each open container (~0 = indefinite)
    constexpr std::uint64_t kIndefinite = ~std::uint64_t{0};
    std::size_t pos = 0;
    auto item_done = [&remaining] {
        while (!remaining.empty() && remaining.back() != kIndefinite) {
            if (--remaining.back() > 0) {
                return;
            }
            remaining.pop_back();
        }
    };
    do {
        if (pos >= b.size()) {
            return false;
        }
        const std::uint8_t ib = b[pos++];
        const unsigned major = ib >> 5;
        const unsigned ai = ib & 31;
        if (ib == 0xff) {  // break: ends the innermost indefinite container
            if (remaining.empty() || remaining.back() != kIndefinite) {
                return false;
            }
            remaining.pop_back();
            item_done();
            continue;
        }
        std::uint64_t arg = ai;
        if (ai >= 24 && ai <= 27) {
            const std::size_t n = std::size_t{1} << (ai - 24);
            if (pos + n > b.size()) {
                return false;
            }
            arg = 0;
            for (std::size_t i = 0; i < n; ++i) {
                arg = (arg << 8) | b[pos++];
            }
        } else if (ai >= 28 && ai != 31) {
            return false;
        }
        const bool indefinite = ai == 31;
        if ((major == 2 || major == 3) && !indefinite) {
            if (arg > b.size() - pos) {
                return false;
            }
            pos += static_cast<std::size_t>(arg);
        }
        if (major == 4 || major == 5 || ((major == 2 || major == 3) && indefinite)) {
            const std::uint64_t count = indefinite ? kIndefinite : (major == 5 ? arg * 2 : arg);
            if (arg > b.size() || remaining.size() >= max_depth) {
                return false;
            }
            if (count != 0) {
                remaining.push_back(count);
                continue;
            }
        } else if (major == 6) {
            continue;  // a tag: the tagged item follows and counts as this one
        }
        item_done();
    } while (!remaining.empty());
    return pos == b.size();
}

constexpr std::size_t kMaxCborDepth = 32;
constexpr std::size_t kTelemetryBody = 27;
constexpr std::size_t kLinkStatsBody = 16;
constexpr std::size_t kJoystickBody = 4;

void encode_body(Writer& w, const Telemetry& t) {
    w.le(twos(clamp_round<std::int64_t>(t.lat_deg * 1e7, -900000000, 900000000), 4), 4);
    w.le(twos(clamp_round<std::int64_t>(t.lon_deg * 1e7, -1800000000, 1800000000), 4), 4);
    w.le(twos(clamp_round<std::int64_t>(t.alt_m * 10, -32768, 32767), 2), 2);
    w.le(clamp_round<std::uint64_t>(t.ground_speed_mps * 100, 0, 65535), 2);
    double heading = std::fmod(t.heading_deg, 360.0);
    if (heading < 0) {
        heading += 360.0;
    }
    w.le(clamp_round<std::uint64_t>(heading * 100, 0, 35999), 2);
    w.le(twos(std::clamp(t.roll_deg, -127, 127), 1), 1);
    w.le(twos(std::clamp(t.pitch_deg, -127, 127), 1), 1);
    w.le(clamp_round<std::uint64_t>(t.battery_v * 1000, 0, 65535), 2);
    w.u8(t.battery_pct ? std::clamp(*t.battery_pct, 0, 100) : 255);
    w.u8((std::min<unsigned>(t.gps_fix, 15) << 4) | std::min<unsigned>(t.satellites, 15));
    w.u8(std::min<unsigned>(t.vehicle_state, 15) | (std::min<unsigned>(t.plan_state, 7) << 4) |
         (t.no_position ? 0x80u : 0u));
    w.u8(t.mode);
    w.le(std::min<unsigned>(t.plan_element, 0x3fff), 2);
    w.le(std::min<std::uint32_t>(t.next_waypoint, 0xffffff), 3);
}

Telemetry decode_telemetry(Reader& r) {
    Telemetry t;
    t.lat_deg = static_cast<double>(r.sle(4)) / 1e7;
    t.lon_deg = static_cast<double>(r.sle(4)) / 1e7;
    t.alt_m = static_cast<double>(r.sle(2)) / 10.0;
    t.ground_speed_mps = static_cast<double>(r.le(2)) / 100.0;
    t.heading_deg = static_cast<double>(r.le(2)) / 100.0;
    t.roll_deg = static_cast<int>(r.sle(1));
    t.pitch_deg = static_cast<int>(r.sle(1));
    t.battery_v = static_cast<double>(r.le(2)) / 1000.0;
    const auto pct = r.le(1);
    if (pct <= 100) {
        t.battery_pct = static_cast<int>(pct);
    }
    const auto gps = r.le(1);
    t.gps_fix = static_cast<std::uint8_t>(gps >> 4);
    t.satellites = static_cast<std::uint8_t>(gps & 0x0f);
    const auto states = r.le(1);
    t.vehicle_state = static_cast<std::uint8_t>(states & 0x0f);
    t.plan_state = static_cast<std::uint8_t>((states >> 4) & 0x07);
    t.no_position = (states & 0x80) != 0;
    t.mode = static_cast<std::uint8_t>(r.le(1));
    t.plan_element = static_cast<std::uint16_t>(r.le(2) & 0x3fff);
    t.next_waypoint = static_cast<std::uint32_t>(r.le(3));
    return t;
}

}  // namespace

namespace {

// A command or result: its CBOR, compressed when that saves bytes (a short one rarely compresses).
void encode_payload(Writer& w, MessageType plain, MessageType deflated, std::uint32_t request_id,
                    const nlohmann::json& value) {
    constexpr std::size_t kWorthCompressing = 48;
    const auto cbor = nlohmann::json::to_cbor(value);
    if (cbor.size() >= kWorthCompressing) {
        const auto packed = deflate_payload(cbor);
        if (!packed.empty() && packed.size() < cbor.size()) {
            w.u8(static_cast<std::uint8_t>(deflated));
            w.le(request_id, 4);
            w.bytes(packed);
            return;
        }
    }
    w.u8(static_cast<std::uint8_t>(plain));
    w.le(request_id, 4);
    w.bytes(cbor);
}

}  // namespace

std::vector<std::uint8_t> encode(const Message& message) {
    Writer w;
    w.u8(kVersion);
    std::visit(
        [&w](const auto& m) {
            using T = std::decay_t<decltype(m)>;
            if constexpr (std::is_same_v<T, Telemetry>) {
                w.u8(static_cast<std::uint8_t>(MessageType::Telemetry));
                encode_body(w, m);
            } else if constexpr (std::is_same_v<T, LinkStatsReport>) {
                w.u8(static_cast<std::uint8_t>(MessageType::LinkStats));
                w.le(m.rtt_ms, 2);
                w.le(m.loss_permille, 2);
                w.le(m.goodput_bps, 4);
                w.le(m.retransmissions, 4);
                w.le(m.mac_failures, 4);
            } else if constexpr (std::is_same_v<T, Event>) {
                w.u8(static_cast<std::uint8_t>(MessageType::Event));
                w.u8(static_cast<std::uint8_t>(m.severity));
                const auto n = std::min(m.text.size(), kMaxEventText);
                w.bytes(std::span(reinterpret_cast<const std::uint8_t*>(m.text.data()), n));
            } else if constexpr (std::is_same_v<T, Command>) {
                encode_payload(w, MessageType::Command, MessageType::CommandDeflated, m.request_id,
                               m.request);
            } else if constexpr (std::is_same_v<T, Result>) {
                encode_payload(w, MessageType::Result, MessageType::ResultDeflated, m.request_id, m.answer);
            } else if constexpr (std::is_same_v<T, Joystick>) {
                w.u8(static_cast<std::uint8_t>(MessageType::Joystick));
                w.le(twos(clamp_round<std::int64_t>(m.steering * 10000, -10000, 10000), 2), 2);
                w.le(twos(clamp_round<std::int64_t>(m.throttle * 10000, -10000, 10000), 2), 2);
            } else if constexpr (std::is_same_v<T, ReceptionReport>) {
                w.u8(static_cast<std::uint8_t>(MessageType::Reception));
                w.le(m.received, 4);
            } else if constexpr (std::is_same_v<T, MavlinkFrames>) {
                w.u8(static_cast<std::uint8_t>(MessageType::MavlinkFrames));
                w.bytes(m.bytes);
            } else {
                w.u8(m.type);
            }
        },
        message);
    return std::move(w.out);
}

DecodeResult decode(std::span<const std::uint8_t> bytes) {
    DecodeResult out;
    Reader r(bytes);
    if (!r.has(2)) {
        out.error = "message shorter than its 2-byte header";
        return out;
    }
    const auto version = r.le(1);
    const auto type = static_cast<std::uint8_t>(r.le(1));
    if (version != kVersion) {
        out.error = "unsupported ground protocol version " + std::to_string(version);
        return out;
    }
    const std::size_t body = bytes.size() - 2;
    auto cbor = [&](std::span<const std::uint8_t> b, nlohmann::json& into) {
        if (!cbor_nesting_ok(b, kMaxCborDepth)) {
            return false;
        }
        into = nlohmann::json::from_cbor(b, true, false);
        return !into.is_discarded();
    };
    switch (static_cast<MessageType>(type)) {
        case MessageType::Telemetry:
            if (body < kTelemetryBody) {
                out.error = "telemetry body too short";
                return out;
            }
            out.message = decode_telemetry(r);  // longer bodies come from newer versions: extra bytes ignored
            return out;
        case MessageType::LinkStats: {
            if (body < kLinkStatsBody) {
                out.error = "link statistics body too short";
                return out;
            }
            LinkStatsReport s;
            s.rtt_ms = static_cast<std::uint16_t>(r.le(2));
            s.loss_permille = static_cast<std::uint16_t>(r.le(2));
            s.goodput_bps = static_cast<std::uint32_t>(r.le(4));
            s.retransmissions = static_cast<std::uint32_t>(r.le(4));
            s.mac_failures = static_cast<std::uint32_t>(r.le(4));
            out.message = s;
            return out;
        }
        case MessageType::Event: {
            if (body < 1 || body > 1 + kMaxEventText) {
                out.error = "event body has a bad length";
                return out;
            }
            Event e;
            const auto sev = r.le(1);
            e.severity = sev <= 2 ? static_cast<Event::Severity>(sev) : Event::Severity::Error;
            const auto text = r.rest();
            e.text.assign(text.begin(), text.end());
            out.message = e;
            return out;
        }
        case MessageType::Command:
        case MessageType::Result:
        case MessageType::CommandDeflated:
        case MessageType::ResultDeflated: {
            if (body < 5) {
                out.error = "command/result body too short";
                return out;
            }
            const auto id = static_cast<std::uint32_t>(r.le(4));
            const bool deflated = type == static_cast<std::uint8_t>(MessageType::CommandDeflated) ||
                                  type == static_cast<std::uint8_t>(MessageType::ResultDeflated);
            std::optional<std::vector<std::uint8_t>> inflated;
            if (deflated) {
                inflated = inflate_payload(r.rest());
                if (!inflated) {
                    out.error =
                        "compressed command/result payload does not inflate (damaged, or larger than " +
                        std::to_string(kMaxInflated) + " bytes)";
                    return out;
                }
            }
            nlohmann::json value;
            if (!cbor(inflated ? std::span<const std::uint8_t>(*inflated) : r.rest(), value)) {
                out.error = "command/result payload is not valid CBOR (or nested deeper than 32)";
                return out;
            }
            if (type == static_cast<std::uint8_t>(MessageType::Command) ||
                type == static_cast<std::uint8_t>(MessageType::CommandDeflated)) {
                out.message = Command{id, std::move(value)};
            } else {
                out.message = Result{id, std::move(value)};
            }
            return out;
        }
        case MessageType::Joystick: {
            if (body < kJoystickBody) {
                out.error = "joystick body too short";
                return out;
            }
            Joystick j;
            j.steering = static_cast<double>(std::clamp<std::int64_t>(r.sle(2), -10000, 10000)) / 10000.0;
            j.throttle = static_cast<double>(std::clamp<std::int64_t>(r.sle(2), -10000, 10000)) / 10000.0;
            out.message = j;
            return out;
        }
        case MessageType::Reception: {
            if (body < 4) {
                out.error = "reception report body too short";
                return out;
            }
            out.message = ReceptionReport{static_cast<std::uint32_t>(r.le(4))};
            return out;
        }
        case MessageType::MavlinkFrames: {
            if (body == 0) {
                out.error = "MAVLink frames message carries no bytes";
                return out;
            }
            const auto frames = r.rest();
            out.message = MavlinkFrames{{frames.begin(), frames.end()}};
            return out;
        }
    }
    out.message = Unknown{type};
    return out;
}

namespace {

constexpr std::array<const char*, 7> kVehicleStates{"UNKNOWN",  "CONFIGURE_CHECK",   "PARKING",
                                                    "DIRECTED", "MANUAL_NAVIGATION", "WAYPOINT_NAVIGATION",
                                                    "MANUAL"};

}  // namespace

const char* vehicle_state_name(std::uint8_t code) {
    return code < kVehicleStates.size() ? kVehicleStates[code] : "?";
}

}  // namespace airseg::groundlink::protocol
