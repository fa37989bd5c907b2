#include "tools/linksim/options.hpp"

#include <functional>
#include <map>

#include "tools/common/cli.hpp"

namespace airseg::linksim {

using toolcommon::UsageError;

const char* usage() {
    return R"(usage: airseg-linksim --a PATH --b PATH [options]

Emulates a pair of transparent serial radios between two pseudo-terminals. PATH A and PATH B become symlinks
to the pty slaves; a program opens each as it would open /dev/ttyUSB0 (and should put it in raw mode). Bytes
written at A come out at B and back, at the serial rate, sharing one air channel the way SiK/3DR, XBee and
XTend radios do, with the impairments below. For two radio pairs (dual serial) run two instances.

Link:
  --baud N              serial rate at both ends, 8N1 (baud/10 bytes/s)        [57600]
  --air-rate BPS        raw air bit rate (bytes/s = BPS/8)                     [serial byte rate]
  --half-duplex         one air channel shared by both directions              [default]
  --full-duplex         one air channel per direction
  --turnaround MS       half duplex: dead air when the sending side changes    [1]
  --packet BYTES        largest air packet                                     [252]
  --packet-overhead B   bytes sent on air with every packet                    [0]
  --buffer BYTES        each radio's serial-side FIFO; overflow is dropped     [2048]
  --latency MS          added delay per air packet
Impairments (each also as -ab / -ba for one direction, e.g. --loss-ab 0.01):
  --loss P              probability a byte is lost
  --ber P               probability a bit is flipped
  --corrupt P           probability a byte arrives with one bit flipped
  --frame-loss P        probability an air packet is lost
  --outage START:DUR    seconds after start, for DUR seconds nothing gets through (repeatable)
  --seed N              seed of the impairment generators (deterministic)      [1]
Control and output:
  --control PATH        Unix datagram socket taking run-time commands (below)
  --stats-interval S    print statistics every S seconds
  --json                statistics as JSON (one object per line)
  --host-backlog BYTES  bytes read from a pty that may wait for the serial line [65536]
  --help

Statistics are printed on exit (SIGINT, SIGTERM): per direction bytes in/out, dropped on overflow, lost,
corrupted, air packets sent/lost, and air utilisation.

Control commands (one per datagram; the reply goes to the sender's bound address):
  outage SECONDS [ab|ba|both]       start an outage now
  loss P [ab|ba|both]               set byte loss
  ber P [ab|ba|both]                set bit error rate
  corrupt P [ab|ba|both]            set per-byte corruption
  frame-loss P [ab|ba|both]         set air packet loss
  latency MS [ab|ba|both]           set added latency
  down a|b    up a|b                switch a radio off / on
  stats                             statistics as JSON
  help
)";
}

namespace {

using Setter = std::function<void(DirectionImpairment&, std::string_view option, std::string_view value)>;

void for_directions(RadioConfig& r, std::string_view suffix,
                    const std::function<void(DirectionImpairment&)>& f) {
    if (suffix.empty() || suffix == "-ab") {
        f(r.impairment[index(Side::A)]);
    }
    if (suffix.empty() || suffix == "-ba") {
        f(r.impairment[index(Side::B)]);
    }
}

}  // namespace

std::optional<LinkSimOptions> parse_options(const std::vector<std::string>& args) {
    using namespace toolcommon;
    LinkSimOptions o;
    const std::map<std::string, Setter, std::less<>> impairments{
        {"--loss", [](DirectionImpairment& d, auto opt, auto v) { d.byte_loss = parse_probability(opt, v); }},
        {"--ber",
         [](DirectionImpairment& d, auto opt, auto v) { d.bit_error_rate = parse_probability(opt, v); }},
        {"--corrupt",
         [](DirectionImpairment& d, auto opt, auto v) { d.byte_corruption = parse_probability(opt, v); }},
        {"--frame-loss",
         [](DirectionImpairment& d, auto opt, auto v) { d.frame_loss = parse_probability(opt, v); }},
        {"--latency",
         [](DirectionImpairment& d, auto opt, auto v) { d.latency = parse_milliseconds(opt, v); }},
        {"--outage",
         [](DirectionImpairment& d, auto opt, auto v) {
             const auto w = parse_window(opt, v);
             d.outages.push_back({w.start, w.length});
         }},
    };
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& arg = args[i];
        auto value = [&]() -> std::string_view {
            if (i + 1 >= args.size()) {
                throw UsageError(arg + ": missing value");
            }
            return args[++i];
        };
        if (arg == "--help" || arg == "-h") {
            return std::nullopt;
        } else if (arg == "--a") {
            o.a_path = value();
        } else if (arg == "--b") {
            o.b_path = value();
        } else if (arg == "--baud") {
            o.radio.baud = static_cast<std::uint32_t>(parse_unsigned(arg, value(), 300, 4'000'000));
        } else if (arg == "--air-rate") {
            o.radio.air_rate_bps = static_cast<std::uint32_t>(parse_unsigned(arg, value(), 300, 100'000'000));
        } else if (arg == "--half-duplex") {
            o.radio.duplex = Duplex::Half;
        } else if (arg == "--full-duplex") {
            o.radio.duplex = Duplex::Full;
        } else if (arg == "--turnaround") {
            o.radio.turnaround = parse_milliseconds(arg, value());
        } else if (arg == "--packet") {
            o.radio.max_air_packet = parse_unsigned(arg, value(), 1, 65536);
        } else if (arg == "--packet-overhead") {
            o.radio.air_packet_overhead = parse_unsigned(arg, value(), 0, 65536);
        } else if (arg == "--buffer") {
            o.radio.radio_buffer = parse_unsigned(arg, value(), 1, 1U << 24);
        } else if (arg == "--seed") {
            o.radio.seed = parse_unsigned(arg, value(), 0, UINT64_MAX);
        } else if (arg == "--control") {
            o.control_path = value();
        } else if (arg == "--stats-interval") {
            o.stats_interval = parse_seconds(arg, value());
        } else if (arg == "--json") {
            o.json = true;
        } else if (arg == "--host-backlog") {
            o.host_backlog = parse_unsigned(arg, value(), 1, 1U << 26);
        } else {
            const auto dash = arg.size() > 3 ? arg.substr(arg.size() - 3) : std::string();
            const bool directed = dash == "-ab" || dash == "-ba";
            const std::string base = directed ? arg.substr(0, arg.size() - 3) : arg;
            auto it = impairments.find(base);
            if (it == impairments.end()) {
                throw UsageError(arg + ": unknown option (see --help)");
            }
            const std::string_view v = value();
            for_directions(o.radio, directed ? std::string_view(dash) : std::string_view(),
                           [&](DirectionImpairment& d) { it->second(d, arg, v); });
        }
    }
    if (o.a_path.empty() || o.b_path.empty()) {
        throw UsageError("--a PATH and --b PATH are both required");
    }
    if (o.a_path == o.b_path) {
        throw UsageError("--a and --b must be different paths");
    }
    if (auto e = o.radio.validate(); !e.empty()) {
        throw UsageError(e);
    }
    return o;
}

}  // namespace airseg::linksim
