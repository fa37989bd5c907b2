// MAVLink codec throughput: parsing a realistic mixed telemetry stream (MB/s, frames/s), and the cost of
// encoding one message (ns per message).
#include <benchmark/benchmark.h>

#include <array>
#include <random>

#include "bench/mavlink/telemetry_stream.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace {

using namespace airseg::mavlink;

const bench::TelemetryStream& stream() {
    static const bench::TelemetryStream s = bench::make_telemetry_stream(60.0);  // one minute of telemetry
    return s;
}

// Whole buffer at once (chunk == 0) or in serial-read-sized pieces.
void BM_ParseTelemetry(benchmark::State& state) {
    const auto& s = stream();
    const auto chunk = static_cast<std::size_t>(state.range(0));
    std::size_t frames = 0;
    for (auto _ : state) {
        Parser parser;
        auto count = [&](const Frame& f) { frames += f.msgid != 0xFFFFFFFF; };
        if (chunk == 0) {
            parser.push(s.bytes, count);
        } else {
            for (std::size_t i = 0; i < s.bytes.size(); i += chunk) {
                parser.push(std::span(s.bytes).subspan(i, std::min(chunk, s.bytes.size() - i)), count);
            }
        }
        benchmark::DoNotOptimize(frames);
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * s.bytes.size()));
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.frames));
    state.counters["stream_bytes"] = static_cast<double>(s.bytes.size());
}
BENCHMARK(BM_ParseTelemetry)->Arg(0)->Arg(64)->Arg(1);

// Parsing plus decoding each frame into its typed struct, as the autopilot driver does.
void BM_ParseAndDecodeTelemetry(benchmark::State& state) {
    const auto& s = stream();
    double sink = 0;
    for (auto _ : state) {
        Parser parser;
        parser.push(s.bytes, [&](const Frame& f) {
            switch (f.msgid) {
                case Attitude::kId:
                    sink += decode_payload<Attitude>(f.payload_view()).yaw;
                    break;
                case GlobalPositionInt::kId:
                    sink += decode_payload<GlobalPositionInt>(f.payload_view()).lat;
                    break;
                case GpsRawInt::kId:
                    sink += decode_payload<GpsRawInt>(f.payload_view()).satellites_visible;
                    break;
                case VfrHud::kId:
                    sink += decode_payload<VfrHud>(f.payload_view()).groundspeed;
                    break;
                case SysStatus::kId:
                    sink += decode_payload<SysStatus>(f.payload_view()).voltage_battery;
                    break;
                default:
                    sink += f.payload_length;
            }
        });
        benchmark::DoNotOptimize(sink);
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * s.bytes.size()));
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.frames));
}
BENCHMARK(BM_ParseAndDecodeTelemetry);

// The same stream after a noisy radio: 1 byte in 1000 corrupted, so the parser keeps resynchronising.
void BM_ParseNoisyTelemetry(benchmark::State& state) {
    auto bytes = stream().bytes;
    std::mt19937 rng(3);
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        if (rng() % 1000 == 0) {
            bytes[i] = static_cast<std::uint8_t>(rng());
        }
    }
    std::size_t frames = 0;
    for (auto _ : state) {
        Parser parser;
        parser.push(bytes, [&](const Frame&) { ++frames; });
        benchmark::DoNotOptimize(frames);
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes.size()));
}
BENCHMARK(BM_ParseNoisyTelemetry);

template <class M>
void encode_one(benchmark::State& state, const M& msg) {
    Encoder encoder(1, 1, state.range(0) == 1 ? Version::V1 : Version::V2);
    std::array<std::uint8_t, kMaxFrameLength> out{};
    for (auto _ : state) {
        benchmark::DoNotOptimize(encoder.encode(msg, out));
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void BM_EncodeHeartbeat(benchmark::State& state) {
    Heartbeat hb;
    hb.type = 10;
    hb.custom_mode = 10;
    encode_one(state, hb);
}
BENCHMARK(BM_EncodeHeartbeat)->Arg(1)->Arg(2);

void BM_EncodeAttitude(benchmark::State& state) {
    Attitude a;
    a.time_boot_ms = 123456;
    a.roll = 0.01f;
    a.pitch = -0.02f;
    a.yaw = 1.5f;
    encode_one(state, a);
}
BENCHMARK(BM_EncodeAttitude)->Arg(2);

void BM_EncodeMissionItemInt(benchmark::State& state) {
    MissionItemInt item;
    item.target_system = 1;
    item.target_component = 1;
    item.seq = 17;
    item.frame = 6;
    item.command = 16;
    item.autocontinue = 1;
    item.x = -353632621;
    item.y = 1491652374;
    item.z = 25.0f;
    encode_one(state, item);
}
BENCHMARK(BM_EncodeMissionItemInt)->Arg(1)->Arg(2);

void BM_EncodeBatteryStatus(benchmark::State& state) {
    BatteryStatus b;
    b.voltages = {4200, 4190, 4185, 65535, 65535, 65535, 65535, 65535, 65535, 65535};
    b.current_battery = 850;
    b.battery_remaining = 87;
    encode_one(state, b);
}
BENCHMARK(BM_EncodeBatteryStatus)->Arg(2);

}  // namespace

BENCHMARK_MAIN();
