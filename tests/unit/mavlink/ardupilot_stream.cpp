#include "tests/unit/mavlink/ardupilot_stream.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>

#include "services/autopilot/mavlink/crc.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/messages.hpp"

namespace airseg::mavlink::test {
namespace {

// splitmix64: integer-only, so a seed gives the same stream on every platform the tests run on.
class Rng {
  public:
    explicit Rng(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        return z ^ (z >> 31);
    }
    std::uint32_t below(std::uint32_t n) { return static_cast<std::uint32_t>(next() % n); }
    bool chance(std::uint32_t per_million) { return below(1000000) < per_million; }

  private:
    std::uint64_t state_;
};

// Undeclared messages an ArduPilot vehicle streams, entries as published for ardupilotmega.xml
// (MAVLINK_MESSAGE_CRCS: id, CRC_EXTRA, minimum length, maximum length).
constexpr std::array<reference::MsgEntry, 18> kUndeclared{{
    {27, 144, 26, 29},     // RAW_IMU
    {29, 115, 14, 16},     // SCALED_PRESSURE
    {32, 185, 28, 28},     // LOCAL_POSITION_NED
    {87, 150, 51, 51},     // POSITION_TARGET_GLOBAL_INT
    {111, 34, 16, 16},     // TIMESYNC
    {116, 76, 22, 24},     // SCALED_IMU2
    {125, 203, 6, 6},      // POWER_STATUS
    {136, 1, 22, 22},      // TERRAIN_REPORT
    {152, 208, 4, 8},      // MEMINFO
    {163, 127, 28, 28},    // AHRS
    {165, 21, 3, 3},       // HWSTATUS
    {178, 47, 24, 24},     // AHRS2
    {193, 71, 22, 26},     // EKF_STATUS_REPORT
    {230, 163, 42, 42},    // ESTIMATOR_STATUS
    {241, 90, 32, 32},     // VIBRATION
    {11030, 144, 44, 44},  // ESC_TELEMETRY_1_TO_4
    {11031, 133, 44, 44},  // ESC_TELEMETRY_5_TO_8
    {11039, 142, 9, 9},    // MCU_STATUS
}};

const reference::MsgEntry& undeclared(std::uint32_t id) {
    return *std::find_if(kUndeclared.begin(), kUndeclared.end(),
                         [id](const reference::MsgEntry& e) { return e.msgid == id; });
}

struct Sender {
    std::uint8_t sysid;
    std::uint8_t compid;
    std::uint8_t seq = 0;
};

class Generator {
  public:
    explicit Generator(std::uint32_t seed) : rng_(seed) {}

    void run(std::size_t bytes) {
        Sender autopilot{1, 1};
        Sender radio{51, 68};
        // 50 Hz scheduler ticks; the rates are the stream rates a ground station typically asks for.
        for (std::uint64_t tick = 0; out_.sent.size() < bytes; ++tick) {
            const std::uint64_t second = tick / 50;
            const std::uint64_t minute = second / 60;
            v1_ = minute % 10 == 3;       // a ground station that speaks MAVLink 1 now and then
            signing_ = minute % 15 == 1;  // and a stretch of signed traffic
            const auto every = [&](std::uint64_t hz_period, std::uint64_t phase) {
                return tick % hz_period == phase % hz_period;
            };
            if (every(50, 0)) {
                declared(autopilot, Heartbeat::kId);
            }
            if (every(25, 3)) {  // EXT_STAT, 2 Hz
                declared(autopilot, SysStatus::kId);
                other(autopilot, 125);
                other(autopilot, 152);
                declared(autopilot, MissionCurrent::kId);
                declared(autopilot, GpsRawInt::kId);
                declared(autopilot, NavControllerOutput::kId);
            }
            if (every(17, 5)) {  // POSITION, 3 Hz
                declared(autopilot, GlobalPositionInt::kId);
                other(autopilot, 32);
            }
            if (every(5, 1)) {  // EXTRA1, 10 Hz
                declared(autopilot, Attitude::kId);
                other(autopilot, 178);
            }
            if (every(12, 7)) {  // EXTRA2, 4 Hz
                declared(autopilot, VfrHud::kId);
            }
            if (every(25, 11)) {  // EXTRA3, 2 Hz
                other(autopilot, 163);
                other(autopilot, 165);
                declared(autopilot, SystemTime::kId);
                other(autopilot, 136);
                declared(autopilot, BatteryStatus::kId);
                other(autopilot, 241);
                other(autopilot, 193);
                other(autopilot, 11030);
                other(autopilot, 11031);
                other(autopilot, 11039);
            }
            if (every(25, 17)) {  // RC_CHAN and RAW_SENS, 2 Hz
                declared(autopilot, ServoOutputRaw::kId);
                declared(autopilot, RcChannels::kId);
                other(autopilot, 27);
                other(autopilot, 116);
                other(autopilot, 29);
                other(autopilot, 87);
                other(autopilot, 230);
            }
            if (every(50, 23)) {
                other(autopilot, 111);
                declared(radio, RadioStatus::kId, /*force_v1=*/true);  // the SiK radio's own frames
            }
            if (every(50, 31) && rng_.chance(150000)) {
                declared(autopilot, Statustext::kId);
            }
            if (every(1500, 41)) {
                declared(autopilot, CommandAck::kId);
            }
            if (every(3000, 29)) {
                declared(autopilot, HomePosition::kId);
            }
            // A parameter download every five minutes: the whole list at up to 20 per tick.
            if (every(15000, 100)) {
                params_left_ = 900;
                declared(autopilot, AutopilotVersion::kId);
            }
            for (int i = 0; i < 20 && params_left_ > 0; ++i, --params_left_) {
                declared(autopilot, ParamValue::kId);
            }
            // A mission download every two minutes.
            if (every(6000, 200)) {
                declared(autopilot, MissionCount::kId);
                items_left_ = 40;
            }
            if (items_left_ > 0 && every(2, 0)) {
                declared(autopilot, MissionItemInt::kId);
                --items_left_;
            }
        }
    }

    NoisyStream take() { return std::move(out_); }
    std::vector<std::size_t>& offsets() { return offsets_; }

  private:
    // Field values as a vehicle's are: many zero (so MAVLink 2 truncates), small integers, floats of
    // every magnitude, full-range identifiers and coordinates.
    void fill(std::uint8_t* p, std::size_t size, bool is_float) {
        const std::uint32_t kind = rng_.below(100);
        std::uint64_t v = 0;
        if (kind < 30) {
            v = 0;
        } else if (is_float) {
            static constexpr std::array<float, 6> kScale{0.001f, 0.01f, 0.1f, 1.0f, 10.0f, 1000.0f};
            const float f = static_cast<float>(static_cast<std::int32_t>(rng_.below(20001)) - 10000) *
                            kScale[rng_.below(kScale.size())];
            std::uint32_t bits = 0;
            std::memcpy(&bits, &f, sizeof bits);
            v = bits;
        } else if (kind < 70) {
            v = rng_.below(200);
        } else {
            v = rng_.next();
        }
        for (std::size_t i = 0; i < size; ++i) {
            p[i] = static_cast<std::uint8_t>(v >> (8 * (i % 8)));
        }
    }

    void text(std::uint8_t* p, std::size_t size) {
        static constexpr std::array<const char*, 6> kWords{
            "ARMING_CHECK",  "WPNAV_SPEED",     "EKF3 IMU0 is using GPS",
            "Mission: 3 WP", "SERVO1_FUNCTION", "PreArm: Battery below minimum"};
        std::string s = kWords[rng_.below(kWords.size())];
        s += std::to_string(rng_.below(100));
        std::memcpy(p, s.data(), std::min(size, s.size()));
    }

    void declared(Sender& from, std::uint32_t id, bool force_v1 = false) {
        const MessageInfo& info = *find_message(id);
        std::array<std::uint8_t, kMaxPayload> payload{};
        for (const FieldInfo& f : info.fields) {
            if (f.type == FieldType::Char) {
                text(payload.data() + f.offset, f.size());
                continue;
            }
            for (std::size_t e = 0; e < f.element_count(); ++e) {
                const std::size_t n = type_size(f.type);
                fill(payload.data() + f.offset + e * n, n, f.type == FieldType::Float);
            }
        }
        emit(from, info.id, info.crc_extra, payload.data(), info.base_length, info.length, true, force_v1);
    }

    void other(Sender& from, std::uint32_t id) {
        const reference::MsgEntry& e = undeclared(id);
        std::array<std::uint8_t, kMaxPayload> payload{};
        for (std::size_t i = 0; i + 4 <= e.max_msg_len; i += 4) {
            fill(payload.data() + i, 4, rng_.below(3) != 0);
        }
        for (std::size_t i = e.max_msg_len & ~std::size_t{3}; i < e.max_msg_len; ++i) {
            fill(payload.data() + i, 1, false);
        }
        // Some are declared by now (TIMESYNC, POSITION_TARGET_GLOBAL_INT): their frames count as declared.
        emit(from, id, e.crc_extra, payload.data(), e.min_msg_len, e.max_msg_len, find_message(id) != nullptr,
             false);
    }

    void emit(Sender& from, std::uint32_t id, std::uint8_t crc_extra, const std::uint8_t* payload,
              std::size_t base_length, std::size_t length, bool is_declared, bool force_v1) {
        const bool v1 = force_v1 || v1_;
        if (v1 && id > 0xFF) {
            return;  // MAVLink 1 cannot carry it; ArduPilot does not send it then
        }
        std::size_t n = v1 ? base_length : length;
        while (!v1 && n > 1 && payload[n - 1] == 0) {
            --n;
        }
        const bool is_signed = !v1 && signing_;
        const std::uint8_t incompat = is_signed ? kIncompatSigned : 0;
        offsets_.push_back(out_.sent.size());
        Bytes& b = out_.sent;
        const std::size_t start = b.size();
        if (v1) {
            b.insert(b.end(), {kMagicV1, static_cast<std::uint8_t>(n), from.seq, from.sysid, from.compid,
                               static_cast<std::uint8_t>(id)});
        } else {
            b.insert(b.end(), {kMagicV2, static_cast<std::uint8_t>(n), incompat, 0, from.seq, from.sysid,
                               from.compid, static_cast<std::uint8_t>(id), static_cast<std::uint8_t>(id >> 8),
                               static_cast<std::uint8_t>(id >> 16)});
        }
        b.insert(b.end(), payload, payload + n);
        Crc16 crc;
        crc.add(std::span<const std::uint8_t>(b.data() + start + 1, b.size() - start - 1));
        crc.add(crc_extra);
        b.push_back(static_cast<std::uint8_t>(crc.value()));
        b.push_back(static_cast<std::uint8_t>(crc.value() >> 8));
        if (is_signed) {
            for (std::size_t i = 0; i < kSignatureLength; ++i) {
                b.push_back(static_cast<std::uint8_t>(rng_.next()));
            }
        }
        SentFrame f;
        f.key = content_key(!v1, incompat, 0, from.seq, from.sysid, from.compid, id, payload, n);
        f.declared = is_declared;
        f.v2 = !v1;
        f.is_signed = is_signed;
        out_.frames.push_back(f);
        ++from.seq;
    }

    Rng rng_;
    NoisyStream out_;
    std::vector<std::size_t> offsets_;  // where each frame starts in out_.sent
    bool v1_ = false;
    bool signing_ = false;
    int params_left_ = 0;
    int items_left_ = 0;
};

}  // namespace

std::uint64_t content_key(bool v2, std::uint8_t incompat_flags, std::uint8_t compat_flags, std::uint8_t seq,
                          std::uint8_t sysid, std::uint8_t compid, std::uint32_t msgid,
                          const std::uint8_t* payload, std::size_t payload_length) {
    std::uint64_t h = 0xCBF29CE484222325ULL;  // FNV-1a
    const auto add = [&h](std::uint64_t byte) { h = (h ^ (byte & 0xFF)) * 0x100000001B3ULL; };
    for (std::uint64_t b :
         {std::uint64_t{v2}, std::uint64_t{incompat_flags}, std::uint64_t{compat_flags}, std::uint64_t{seq},
          std::uint64_t{sysid}, std::uint64_t{compid}, std::uint64_t{msgid}, std::uint64_t{msgid >> 8},
          std::uint64_t{msgid >> 16}, std::uint64_t{payload_length}}) {
        add(b);
    }
    for (std::size_t i = 0; i < payload_length; ++i) {
        add(payload[i]);
    }
    return h;
}

NoisyStream make_ardupilot_stream(std::size_t bytes, std::uint32_t seed, const LineNoise& noise) {
    Generator g(seed);
    g.run(bytes);
    const std::vector<std::size_t> offsets = std::move(g.offsets());
    NoisyStream s = g.take();

    Rng rng(std::uint64_t{seed} * 0x2545F4914F6CDD1DULL + 1);
    const auto threshold = static_cast<std::uint64_t>(noise.byte_error_rate * 18446744073709551615.0);
    const auto loss = static_cast<std::uint32_t>(noise.loss_share * 1e6);
    const auto insertion = static_cast<std::uint32_t>(noise.insertion_share * 1e6);
    s.received.reserve(s.sent.size() + s.sent.size() / 1000);
    for (auto& f : s.frames) {
        f.intact = true;
    }
    std::size_t frame = 0;
    for (std::size_t i = 0; i < s.sent.size(); ++i) {
        while (frame + 1 < offsets.size() && offsets[frame + 1] <= i) {
            ++frame;
        }
        const std::uint8_t byte = s.sent[i];
        if (i == offsets[frame]) {
            s.frames[frame].received_at = s.received.size();
        }
        if (rng.next() >= threshold) {
            s.received.push_back(byte);
            continue;
        }
        const std::uint32_t kind = rng.below(1000000);
        if (kind < loss) {
            ++s.losses;
            s.frames[frame].intact = false;
        } else if (kind < loss + insertion) {
            ++s.insertions;
            s.received.push_back(static_cast<std::uint8_t>(rng.next()));
            s.received.push_back(byte);
            if (i != offsets[frame]) {  // before a frame's first byte it is not inside the frame
                s.frames[frame].intact = false;
            }
        } else {
            ++s.flips;
            s.received.push_back(static_cast<std::uint8_t>(byte ^ (1u << rng.below(8))));
            s.frames[frame].intact = false;
        }
    }
    return s;
}

std::vector<reference::MsgEntry> declared_entries() {
    std::vector<reference::MsgEntry> out;
    for (const MessageInfo& m : all_messages()) {
        out.push_back({m.id, m.crc_extra, m.base_length, m.length});
    }
    return out;  // all_messages() is ordered by id
}

std::vector<reference::MsgEntry> ardupilot_entries() {
    std::vector<reference::MsgEntry> out = declared_entries();
    std::copy_if(kUndeclared.begin(), kUndeclared.end(), std::back_inserter(out),
                 [](const reference::MsgEntry& e) { return find_message(e.msgid) == nullptr; });
    std::sort(out.begin(), out.end(),
              [](const reference::MsgEntry& a, const reference::MsgEntry& b) { return a.msgid < b.msgid; });
    return out;
}

}  // namespace airseg::mavlink::test
