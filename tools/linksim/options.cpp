#include "tools/linksim/options.hpp"

#include <functional>

#include "cli/command_line.hpp"

namespace airseg::linksim {

using cli::UsageError;

namespace {

constexpr const char* kUsageHead = R"(usage: airseg-linksim --a PATH --b PATH [options]

Emulates a pair of transparent serial radios between two pseudo-terminals. PATH A and PATH B become symlinks
to the pty slaves; a program opens each as it would open /dev/ttyUSB0 (and should put it in raw mode). Bytes
written at A come out at B and back, at the serial rate, sharing one air channel the way SiK/3DR, XBee and
XTend radios do, with the impairments below. For two radio pairs (dual serial) run two instances.

)";

constexpr const char* kUsageTail = R"(
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

using Setter = std::function<void(DirectionImpairment&, std::string_view option, std::string_view value)>;

/// An impairment as --NAME (both directions) and --NAME-ab / --NAME-ba (one).
void add_impairment(cli::OptionTable& table, RadioConfig& radio, const std::string& name,
                    const char* value_name, const std::string& help, const Setter& set) {
    for (const std::string suffix : {"", "-ab", "-ba"}) {
        const auto option = name + suffix;
        const auto text = suffix.empty()
                              ? help
                              : "the same, from " + suffix.substr(1, 1) + " to " + suffix.substr(2) + " only";
        table.value(option.c_str(), value_name, text.c_str(),
                    [&radio, suffix, set](std::string_view opt, std::string_view v) {
                        if (suffix != "-ba") {
                            set(radio.impairment[index(Side::A)], opt, v);
                        }
                        if (suffix != "-ab") {
                            set(radio.impairment[index(Side::B)], opt, v);
                        }
                    });
    }
}

/// The options in the order --help lists them; they act in command-line order.
void fill_table(cli::OptionTable& table, LinkSimOptions& o) {
    using namespace cli;
    table.value("a", "PATH", "symlink to create to radio A's pty slave (required)", text(o.a_path))
        .value("b", "PATH", "symlink to create to radio B's pty slave (required)", text(o.b_path))
        .value("baud", "N", "serial rate at both ends, 8N1 (baud/10 bytes/s) [57600]",
               number(o.radio.baud, 300, 4'000'000))
        .value("air-rate", "BPS", "raw air bit rate (bytes/s = BPS/8) [serial byte rate]",
               number(o.radio.air_rate_bps, 300, 100'000'000))
        .flag("half-duplex", "one air channel shared by both directions [default]",
              [&] { o.radio.duplex = Duplex::Half; })
        .flag("full-duplex", "one air channel per direction", [&] { o.radio.duplex = Duplex::Full; })
        .value("turnaround", "MS", "half duplex: dead air when the sending side changes [1]",
               in_milliseconds(o.radio.turnaround))
        .value("packet", "BYTES", "largest air packet [252]", number(o.radio.max_air_packet, 1, 65536))
        .value("packet-overhead", "B", "bytes sent on air with every packet [0]",
               number(o.radio.air_packet_overhead, 0, 65536))
        .value("buffer", "BYTES", "each radio's serial-side FIFO; overflow is dropped [2048]",
               number(o.radio.radio_buffer, 1, 1U << 24))
        .value("usb-latency", "MS",
               "both hosts reach their radio through a USB serial adapter (FTDI class) with this latency "
               "timer, 1..255 (FTDI's default is 16); 0: bytes reach the host as they leave the UART [0]",
               [&o](std::string_view opt, std::string_view v) {
                   o.radio.usb_latency[index(Side::A)] = parse_milliseconds(opt, v);
                   o.radio.usb_latency[index(Side::B)] = o.radio.usb_latency[index(Side::A)];
               })
        .value("usb-latency-a", "MS", "the same, host A's adapter only",
               in_milliseconds(o.radio.usb_latency[index(Side::A)]))
        .value("usb-latency-b", "MS", "the same, host B's adapter only",
               in_milliseconds(o.radio.usb_latency[index(Side::B)]))
        .value("usb-packet", "BYTES", "data bytes per USB packet of an adapter [62]",
               number(o.radio.usb_packet, 1, 65536));
    // Each impairment also as --NAME-ab / --NAME-ba for one direction, e.g. --loss-ab 0.01.
    add_impairment(table, o.radio, "latency", "MS", "added delay per air packet",
                   [](DirectionImpairment& d, auto opt, auto v) { d.latency = parse_milliseconds(opt, v); });
    add_impairment(table, o.radio, "loss", "P", "probability a byte is lost",
                   [](DirectionImpairment& d, auto opt, auto v) { d.byte_loss = parse_probability(opt, v); });
    add_impairment(
        table, o.radio, "ber", "P", "probability a bit is flipped",
        [](DirectionImpairment& d, auto opt, auto v) { d.bit_error_rate = parse_probability(opt, v); });
    add_impairment(
        table, o.radio, "corrupt", "P", "probability a byte arrives with one bit flipped",
        [](DirectionImpairment& d, auto opt, auto v) { d.byte_corruption = parse_probability(opt, v); });
    add_impairment(
        table, o.radio, "frame-loss", "P", "probability an air packet is lost",
        [](DirectionImpairment& d, auto opt, auto v) { d.frame_loss = parse_probability(opt, v); });
    add_impairment(table, o.radio, "outage", "START:DUR",
                   "seconds after start, for DUR seconds nothing gets through (repeatable)",
                   [](DirectionImpairment& d, auto opt, auto v) {
                       const auto w = parse_window(opt, v);
                       d.outages.push_back({w.start, w.length});
                   });
    table
        .value("seed", "N", "seed of the impairment generators (deterministic) [1]",
               number(o.radio.seed, 0, UINT64_MAX))
        .value("control", "PATH", "Unix datagram socket taking run-time commands (below)",
               text(o.control_path))
        .value("stats-interval", "S", "print statistics every S seconds", in_seconds(o.stats_interval))
        .flag("json", "statistics as JSON (one object per line)", [&] { o.json = true; })
        .value("host-backlog", "BYTES", "bytes read from a pty that may wait for the serial line [65536]",
               number(o.host_backlog, 1, 1U << 26))
        .help_and_version(false);
}

}  // namespace

std::string usage() {
    LinkSimOptions unused;
    cli::OptionTable table("Options");
    fill_table(table, unused);
    return std::string(kUsageHead) + cli::describe(table) + kUsageTail;
}

std::optional<LinkSimOptions> parse_options(const std::vector<std::string>& args) {
    LinkSimOptions o;
    cli::OptionTable table;
    fill_table(table, o);
    parse(args, table);
    if (table.help_requested()) {
        return std::nullopt;
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
