// airseg-mavdump: MAVLink byte streams to JSON lines, and back with --encode. See --help.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cli/command_line.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "tools/mavdump/frame_json.hpp"
#include "tools/mavdump/tlog_reader.hpp"

namespace {

constexpr std::string_view kUsage = R"(Usage: airseg-mavdump [--tlog | --raw] [FILE]
       airseg-mavdump --encode [FILE] [-o OUTPUT]

Decodes a MAVLink v1/v2 byte stream into one JSON object per line on standard output:
  {"name":"HEARTBEAT","msgid":0,"sysid":1,"compid":1,"seq":7,"v":2,"fields":{"type":10,...}}
Field names are those of the MAVLink specification; char[] fields are strings, arrays are JSON arrays,
float NaN and infinities are "nan", "inf", "-inf". Signed frames carry "signed":true (the signature is
not checked). Every message of ArduPilot's dialect is decoded (its checksum verified); an id outside it
is printed as "name":"UNKNOWN_<id>" with its raw "payload" in hex (its checksum cannot be verified). A summary of good and bad frames goes to standard
error as the last line: {"summary":{...}}.

FILE is read instead of standard input when given ("-" is standard input). A FILE ending in .tlog is read
as a telemetry log (8-byte big-endian microsecond timestamp before each frame) and each line then starts
with "timestamp_us".

)";

struct Options {
    bool encode = false;
    bool list_messages = false;
    enum class Format { Auto, Raw, Tlog } format = Format::Auto;
    std::string input = "-";
    std::string output = "-";
};

std::FILE* open_or_std(const std::string& path, const char* mode, std::FILE* fallback) {
    return path == "-" ? fallback : std::fopen(path.c_str(), mode);
}

int decode(const Options& opt, std::FILE* in, std::FILE* out) {
    using airseg::mavlink::Frame;
    airseg::mavlink::Parser parser;
    airseg::mavdump::TlogReader tlog;
    const bool is_tlog =
        opt.format == Options::Format::Tlog || (opt.format == Options::Format::Auto && opt.input.size() > 5 &&
                                                opt.input.compare(opt.input.size() - 5, 5, ".tlog") == 0);
    std::string line;
    std::uint64_t timestamp = 0;
    auto print = [&](const Frame& f) {
        line = airseg::mavdump::frame_to_json(f, is_tlog ? std::optional(timestamp) : std::nullopt);
        line += '\n';
        std::fwrite(line.data(), 1, line.size(), out);
    };
    std::vector<std::uint8_t> chunk(1 << 16);
    while (true) {
        const std::size_t n = std::fread(chunk.data(), 1, chunk.size(), in);
        if (n == 0) {
            break;
        }
        const std::span<const std::uint8_t> bytes(chunk.data(), n);
        if (is_tlog) {
            tlog.push(bytes, [&](std::uint64_t t, std::span<const std::uint8_t> frame) {
                timestamp = t;
                parser.push(frame, print);
                parser.finish(print);  // a record holds exactly one frame
            });
        } else {
            parser.push(bytes, print);
        }
    }
    if (std::ferror(in)) {
        std::fprintf(stderr, "airseg-mavdump: read error on %s: %s\n", opt.input.c_str(),
                     std::strerror(errno));
        return 1;
    }
    parser.finish(print);
    tlog.finish();
    const auto& s = parser.stats();
    std::fprintf(
        stderr,
        "{\"summary\":{\"frames_ok\":%llu,\"unknown_msgid\":%llu,\"bad_checksum\":%llu,\"truncated\":%llu,"
        "\"garbage_bytes\":%llu,\"incompat_rejected\":%llu,\"signed_frames\":%llu,\"seq_lost\":%llu%s}}\n",
        static_cast<unsigned long long>(s.frames_ok), static_cast<unsigned long long>(s.unknown_msgid),
        static_cast<unsigned long long>(s.bad_checksum), static_cast<unsigned long long>(s.truncated),
        static_cast<unsigned long long>(s.garbage_bytes + tlog.skipped_bytes()),
        static_cast<unsigned long long>(s.incompat_rejected),
        static_cast<unsigned long long>(s.signed_frames), static_cast<unsigned long long>(s.seq_lost),
        is_tlog ? ",\"format\":\"tlog\"" : "");
    return 0;
}

int encode(const Options& opt, std::istream& in, std::FILE* out) {
    airseg::mavdump::JsonFrameEncoder encoder;
    std::string line;
    unsigned long long line_number = 0;
    unsigned long long frames = 0;
    unsigned long long errors = 0;
    while (std::getline(in, line)) {
        ++line_number;
        if (line.find_first_not_of(" \t\r") == std::string::npos) {
            continue;
        }
        const auto result = encoder.encode_line(line);
        if (!result.error.empty()) {
            ++errors;
            std::fprintf(stderr, "airseg-mavdump: %s:%llu: %s\n",
                         opt.input == "-" ? "<stdin>" : opt.input.c_str(), line_number, result.error.c_str());
            continue;
        }
        std::fwrite(result.frame.data(), 1, result.frame.size(), out);
        ++frames;
    }
    std::fprintf(stderr, "{\"summary\":{\"lines\":%llu,\"frames\":%llu,\"errors\":%llu}}\n", line_number,
                 frames, errors);
    return errors == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    Options opt;
    airseg::cli::OptionTable table("Options");
    table
        .flag("tlog", "read the input as a telemetry log whatever its name",
              [&] { opt.format = Options::Format::Tlog; })
        .flag("raw", "read the input as a plain byte stream whatever its name",
              [&] { opt.format = Options::Format::Raw; })
        .flag("encode",
              "the reverse: JSON lines in (the format above; \"v\" 1 or 2 selects the framing, default 2; "
              "\"sysid\" default 255, \"compid\" default 190, \"seq\" default counts up per sysid/compid; "
              "missing fields are 0, HEARTBEAT.mavlink_version 3), MAVLink frames out. Lines that cannot be "
              "encoded are reported on standard error with their line number and skipped; the exit status "
              "is then 1.",
              [&] { opt.encode = true; })
        .flag("messages",
              "list the messages it knows, ArduPilot's dialect, one JSON line each: name, msgid, crc_extra, "
              "min_length, length, typed (decoded by the daemon) and the fields in declaration order (name, "
              "type, \"length\" for arrays, \"extension\":true for extensions)",
              [&] { opt.list_messages = true; })
        .value(",o", "OUTPUT", "write to OUTPUT instead of standard output", airseg::cli::text(opt.output))
        .help_and_version(false);
    const airseg::cli::Program program{
        "airseg-mavdump", [&table] { return std::string(kUsage) + airseg::cli::describe(table); }};
    const auto line = airseg::cli::run(program, std::vector<std::string>(argv + 1, argv + argc), table,
                                       std::cout, std::cerr, {.max = 1});
    if (line.exit_code) {
        return *line.exit_code;
    }
    if (!line.operands.empty()) {
        opt.input = line.operands.front();
    }
    std::FILE* out = open_or_std(opt.output, "wb", stdout);
    if (out == nullptr) {
        std::fprintf(stderr, "airseg-mavdump: cannot write %s: %s\n", opt.output.c_str(),
                     std::strerror(errno));
        return 1;
    }
    int status = 0;
    if (opt.list_messages) {
        for (const auto& m : airseg::mavlink::dialect_messages()) {
            const std::string text = airseg::mavdump::message_to_json(m) + '\n';
            std::fwrite(text.data(), 1, text.size(), out);
        }
    } else if (opt.encode) {
        if (opt.input == "-") {
            status = encode(opt, std::cin, out);
        } else {
            std::ifstream in(opt.input);
            if (!in) {
                std::fprintf(stderr, "airseg-mavdump: cannot read %s\n", opt.input.c_str());
                return 1;
            }
            status = encode(opt, in, out);
        }
    } else {
        std::FILE* in = open_or_std(opt.input, "rb", stdin);
        if (in == nullptr) {
            std::fprintf(stderr, "airseg-mavdump: cannot read %s: %s\n", opt.input.c_str(),
                         std::strerror(errno));
            return 1;
        }
        status = decode(opt, in, out);
        if (in != stdin) {
            std::fclose(in);
        }
    }
    if (std::fflush(out) != 0) {
        std::fprintf(stderr, "airseg-mavdump: write error on %s: %s\n", opt.output.c_str(),
                     std::strerror(errno));
        return 1;
    }
    if (out != stdout) {
        std::fclose(out);
    }
    return status;
}
