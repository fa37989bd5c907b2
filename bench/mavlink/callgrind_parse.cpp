// Instruction counts of the MAVLink receive path, for callgrind (bench/mavlink/callgrind.sh runs it).
//
//   bench_mavlink_callgrind parse|parse-decode|reference READ_SIZE
//       feeds one minute of ArduPilot telemetry (telemetry_stream.hpp) to airseg's parser (optionally
//       decoding every frame into its typed struct) or to the in-tree model of the C library's
//       mavlink_parse_char(), READ_SIZE bytes per read;
//   bench_mavlink_callgrind decode
//       decodes every frame of that stream once more, already parsed;
//   bench_mavlink_callgrind write-stream FILE | write-crcs FILE
//       writes the stream, or a MAVLINK_MESSAGE_CRCS table of airseg's messages, for clib_parse.c.
//
// Only the measured loop is collected (CALLGRIND_TOGGLE_COLLECT, run with --collect-atstart=no), so
// generating the stream does not count. Each run prints the bytes (or messages) it measured; the script
// divides callgrind's total by that. Natively the toggles do nothing.
#include <valgrind/callgrind.h>

#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/mavlink/telemetry_stream.hpp"
#include "cli/command_line.hpp"
#include "services/autopilot/mavlink/message_table.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tests/unit/mavlink/reference_parser.hpp"

namespace {

using namespace airseg::mavlink;

// Keeps a decoded struct alive, so that the compiler cannot drop the fields nobody reads.
template <class T>
void keep(const T& value) {
    asm volatile("" : : "g"(&value) : "memory");
}

template <class M, class Field>
double decode_one(const Frame& f, Field M::*field) {
    const auto m = decode<M>(f);
    keep(m);
    return static_cast<double>((*m).*field);
}

// The messages of the telemetry stream, each decoded into its struct; one field of each is summed, the
// same one clib_parse.c sums.
double decode_frame(const Frame& f) {
    switch (f.msgid) {
        case Heartbeat::kId:
            return decode_one(f, &Heartbeat::custom_mode);
        case SysStatus::kId:
            return decode_one(f, &SysStatus::voltage_battery);
        case SystemTime::kId:
            return decode_one(f, &SystemTime::time_boot_ms);
        case GpsRawInt::kId:
            return decode_one(f, &GpsRawInt::satellites_visible);
        case Attitude::kId:
            return decode_one(f, &Attitude::yaw);
        case GlobalPositionInt::kId:
            return decode_one(f, &GlobalPositionInt::lat);
        case ServoOutputRaw::kId:
            return decode_one(f, &ServoOutputRaw::servo1_raw);
        case MissionCurrent::kId:
            return decode_one(f, &MissionCurrent::seq);
        case NavControllerOutput::kId:
            return decode_one(f, &NavControllerOutput::wp_dist);
        case RcChannels::kId:
            return decode_one(f, &RcChannels::chan3_raw);
        case VfrHud::kId:
            return decode_one(f, &VfrHud::groundspeed);
        case RadioStatus::kId:
            return decode_one(f, &RadioStatus::rssi);
        case BatteryStatus::kId:
            return decode_one(f, &BatteryStatus::current_consumed);
        case Statustext::kId:
            return decode_one(f, &Statustext::severity);
        default:
            return 0;
    }
}

struct Result {
    std::size_t frames = 0;
    double sink = 0;
};

__attribute__((noinline)) Result run_airseg(std::span<const std::uint8_t> bytes, std::size_t read_size,
                                            bool with_decode) {
    Result r;
    Parser parser;
    auto on_frame = [&](const Frame& f) {
        ++r.frames;
        if (with_decode) {
            r.sink += decode_frame(f);
        }
    };
    CALLGRIND_TOGGLE_COLLECT;
    for (std::size_t i = 0; i < bytes.size(); i += read_size) {
        parser.push(bytes.subspan(i, std::min(read_size, bytes.size() - i)), on_frame);
    }
    CALLGRIND_TOGGLE_COLLECT;
    return r;
}

std::vector<reference::MsgEntry> reference_table() {
    std::vector<reference::MsgEntry> table;
    for (const MessageInfo& m : all_messages()) {
        table.push_back({m.id, m.crc_extra, m.base_length, m.length});
    }
    return table;
}

__attribute__((noinline)) Result run_reference(std::span<const std::uint8_t> bytes, std::size_t read_size) {
    Result r;
    reference::ReferenceParser parser(reference_table());
    CALLGRIND_TOGGLE_COLLECT;
    for (std::size_t i = 0; i < bytes.size(); i += read_size) {
        for (const std::uint8_t c : bytes.subspan(i, std::min(read_size, bytes.size() - i))) {
            r.frames += parser.parse_char(c);
        }
    }
    CALLGRIND_TOGGLE_COLLECT;
    return r;
}

__attribute__((noinline)) Result run_decode(std::span<const std::uint8_t> bytes) {
    std::vector<Frame> frames;
    Parser parser;
    parser.push(bytes, [&](const Frame& f) { frames.push_back(f); });
    Result r;
    CALLGRIND_TOGGLE_COLLECT;
    for (const Frame& f : frames) {
        r.sink += decode_frame(f);
    }
    CALLGRIND_TOGGLE_COLLECT;
    r.frames = frames.size();
    return r;
}

bool write_file(const char* path, std::string_view text) {
    std::FILE* f = std::fopen(path, "wb");
    if (f == nullptr) {
        std::perror(path);
        return false;
    }
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    return std::fclose(f) == 0 && ok;
}

// The C library's table of message entries ({msgid, crc_extra, min_len, max_len, flags, target offsets}),
// for the same messages airseg knows, so that both look an id up in a table of the same size.
std::string crc_table() {
    std::string out = "#define MAVLINK_MESSAGE_CRCS {";
    char entry[64];
    for (const MessageInfo& m : all_messages()) {
        std::snprintf(entry, sizeof entry, "{%u, %u, %u, %u, 0, 0, 0}, ", static_cast<unsigned>(m.id),
                      static_cast<unsigned>(m.crc_extra), static_cast<unsigned>(m.base_length),
                      static_cast<unsigned>(m.length));
        out += entry;
    }
    out += "}\n";
    return out;
}

constexpr const char* kProgram = "bench_mavlink_callgrind";

std::string help(const airseg::cli::OptionTable& table) {
    return std::string("Usage: ") + kProgram + " parse|parse-decode|reference READ_SIZE\n       " + kProgram +
           " decode\n       " + kProgram +
           " write-stream|write-crcs FILE\n\n"
           "Instruction counts of the MAVLink receive path on one minute of ArduPilot telemetry, for "
           "callgrind\n(bench/mavlink/callgrind.sh).\n\n" +
           airseg::cli::describe(table);
}

/// How many operands follow each mode word.
std::optional<std::size_t> operands_of(std::string_view mode) {
    if (mode == "parse" || mode == "parse-decode" || mode == "reference" || mode == "write-stream" ||
        mode == "write-crcs") {
        return 1;
    }
    if (mode == "decode") {
        return 0;
    }
    return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
    airseg::cli::OptionTable table("Options");
    table.help_and_version(false);
    const airseg::cli::Program program{kProgram, [&table] { return help(table); }};
    const auto line = airseg::cli::run(program, std::vector<std::string>(argv + 1, argv + argc), table,
                                       std::cout, std::cerr, {.max = 2});
    if (line.exit_code) {
        return *line.exit_code;
    }
    const auto& words = line.operands;
    if (words.empty()) {
        return airseg::cli::usage_error(std::cerr, kProgram, "missing the mode word");
    }
    const std::string_view mode = words[0];
    const auto wanted = operands_of(mode);
    if (!wanted) {
        return airseg::cli::usage_error(std::cerr, kProgram, "unknown mode '" + words[0] + "'");
    }
    if (words.size() != *wanted + 1) {
        return airseg::cli::usage_error(
            std::cerr, kProgram,
            words.size() > *wanted + 1
                ? "unexpected argument '" + words.back() + "'"
                : std::string(mode.starts_with("write") ? "FILE" : "READ_SIZE") + ": missing value");
    }
    std::size_t read_size = 0;
    if (mode == "parse" || mode == "parse-decode" || mode == "reference") {
        try {
            read_size = static_cast<std::size_t>(airseg::cli::parse_unsigned(
                "READ_SIZE", words[1], 1, std::numeric_limits<std::uint32_t>::max()));
        } catch (const airseg::cli::UsageError& e) {
            return airseg::cli::usage_error(std::cerr, kProgram, e.what());
        }
    }
    const bench::TelemetryStream stream = bench::make_telemetry_stream(60.0);
    const std::span<const std::uint8_t> bytes(stream.bytes);
    if (mode == "write-stream") {
        return write_file(words[1].c_str(),
                          std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()))
                   ? 0
                   : 1;
    }
    if (mode == "write-crcs") {
        return write_file(words[1].c_str(), crc_table()) ? 0 : 1;
    }
    Result r;
    if (mode == "decode") {
        r = run_decode(bytes);
        std::printf("messages %zu sink %g\n", r.frames, r.sink);
        return r.frames == stream.frames ? 0 : 1;
    }
    if (mode == "reference") {
        r = run_reference(bytes, read_size);
    } else {
        r = run_airseg(bytes, read_size, mode == "parse-decode");
    }
    std::printf("bytes %zu frames %zu sink %g\n", bytes.size(), r.frames, r.sink);
    return r.frames == stream.frames ? 0 : 1;
}
