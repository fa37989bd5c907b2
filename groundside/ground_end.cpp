#include "groundside/ground_end.hpp"

#include <fmt/format.h>

#include <cmath>
#include <random>

#include "hal/serial_port.hpp"
#include "hal/udp_socket.hpp"
#include "services/groundlink/link/key_file.hpp"

namespace airseg::groundside {

namespace gl = airseg::groundlink;
namespace proto = airseg::groundlink::protocol;

std::string validate(const RadioOptions& o) {
    if (!o.udp.empty()) {
        if (!o.ports.empty()) {
            return "--udp and --link exclude each other";
        }
        if (o.profile_given) {
            return "--radio describes serial radios; it does not apply to --udp";
        }
        const auto colon = o.udp.rfind(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == o.udp.size()) {
            return "--udp needs HOST:PORT";
        }
        return {};
    }
    if (o.ports.empty() || o.ports.size() > 2) {
        return "--link needs one or two comma-separated serial devices";
    }
    if (o.mode != "single" && o.mode != "split" && o.mode != "redundant") {
        return "--mode must be single, split or redundant";
    }
    if ((o.mode == "single") != (o.ports.size() == 1)) {
        return o.ports.size() == 1 ? "--mode " + o.mode + " needs two --link devices"
                                   : "two --link devices need --mode split or redundant";
    }
    if (!hal::is_supported_baud(o.baud)) {
        return fmt::format("--baud {} is not a supported baud rate", o.baud);
    }
    return {};
}

GroundEnd::GroundEnd(Strand strand, RadioOptions options, Handlers handlers)
    : strand_(std::move(strand)),
      options_(std::move(options)),
      handlers_(std::move(handlers)),
      report_timer_(strand_) {}

GroundEnd::~GroundEnd() {
    stop();
}

std::string GroundEnd::open() {
    gl::TransportConfig t;
    if (!options_.udp.empty()) {
        t.half_duplex = false;
        t.link_rate_bytes_per_s = 1e6;
    } else {
        t.link_rate_bytes_per_s = options_.baud / 10.0;
        options_.profile.apply(t, t.link_rate_bytes_per_s);
        t.paths = options_.ports.size();
        t.path_mode = options_.mode == "split"       ? gl::PathMode::Split
                      : options_.mode == "redundant" ? gl::PathMode::Redundant
                                                     : gl::PathMode::Single;
        // The vehicle transmits on its first pair in split mode, so the ground transmits on the second.
        t.split_tx_path = t.paths == 2 ? 1 : 0;
    }
    if (!options_.key_file.empty()) {
        auto key = gl::read_key_file(options_.key_file);
        if (!key.key) {
            return key.error;
        }
        t.key = key.key;
        keyed_ = true;
    }
    std::random_device rd;
    t.boot_nonce = (static_cast<std::uint64_t>(rd()) << 32) | rd() | 1;
    // Probes only on their own timer, and the reception report in their place (reception_report_timing.hpp):
    // every frame on the idle uplink is a wake-up of the vehicle's daemon.
    t.probe_with_next_poll = false;
    driver_ = std::make_unique<gl::LinkDriver>(
        strand_, t,
        gl::LinkDriver::Handlers{[this](gl::Delivered m) { on_delivered(std::move(m)); },
                                 [this](const gl::TransportEvent& e) {
                                     if (e.kind == gl::TransportEvent::Kind::SessionEstablished ||
                                         e.kind == gl::TransportEvent::Kind::PeerRestarted) {
                                         pushed_received_ = 0;  // the vehicle counts per session too
                                     }
                                     if (handlers_.on_event) {
                                         handlers_.on_event(e);
                                     }
                                 }});
    do_report();
    if (!options_.udp.empty()) {
        const auto colon = options_.udp.rfind(':');
        hal::UdpConfig u;
        u.bind_address = "0.0.0.0";
        u.remote_address = options_.udp.substr(0, colon);
        u.remote_port = static_cast<std::uint16_t>(std::stoul(options_.udp.substr(colon + 1)));
        udp_ = std::make_unique<hal::UdpSocket>(strand_);
        auto r = udp_->open(u);
        if (!r.ok()) {
            return r.message;
        }
        udp_->start_receiving(
            [this](std::span<const std::uint8_t> d, const hal::UdpSocket::Endpoint&) { on_bytes(0, d); },
            [](std::error_code, const std::string&) {});
        driver_->set_writer(0, [this](std::vector<std::uint8_t> f) {
            return udp_->send(std::move(f)) == hal::WriteResult::Queued;
        });
        return {};
    }
    for (std::size_t i = 0; i < options_.ports.size(); ++i) {
        auto port = std::make_unique<hal::SerialPort>(strand_);
        hal::SerialConfig c;
        c.path = options_.ports[i];
        c.baud = options_.baud;
        auto r = port->open(c);
        if (!r.ok()) {
            return r.message.empty() ? "cannot open " + c.path : r.message;
        }
        port->start_reading([this, i](std::span<const std::uint8_t> b) { on_bytes(i, b); },
                            [this, i](std::error_code, const std::string&) { driver_->set_writer(i, {}); });
        auto* raw = port.get();
        ports_.push_back(std::move(port));
        driver_->set_writer(i, [raw](std::vector<std::uint8_t> f) {
            return raw->write(std::move(f)) == hal::WriteResult::Queued;
        });
    }
    return {};
}

void GroundEnd::stop() {
    if (stopped_) {
        return;
    }
    stopped_ = true;
    report_timer_.cancel();
    if (driver_) {
        driver_->stop();
    }
    for (auto& port : ports_) {
        port->close();
    }
    if (udp_) {
        udp_->close();
    }
}

gl::SendResult GroundEnd::send_safe(std::uint8_t priority, const proto::Message& message) {
    return driver_->send_safe(priority, proto::encode(message));
}

gl::SendResult GroundEnd::send_fast(std::uint8_t priority, std::uint16_t topic,
                                    const proto::Message& message) {
    return driver_->send_fast(priority, topic, proto::encode(message));
}

std::size_t GroundEnd::max_message_size() const {
    return driver_->core().config().max_message_size;
}

nlohmann::json GroundEnd::link_stats() const {
    const auto& s = driver_->stats();
    nlohmann::json out{{"link", driver_->link_up() ? "up" : "down"},
                       {"rtt_ms", std::round(s.srtt_ms)},
                       {"loss", std::round(s.frame_loss * 1000) / 1000},
                       {"frames_sent", s.frames_sent},
                       {"frames_received", s.frames_received},
                       {"crc_errors", s.crc_errors},
                       {"mac_failures", s.mac_failures},
                       {"authenticated", s.authenticated}};
    if (auto why = authorisation_problem(); !why.empty()) {
        out["key_problem"] = std::move(why);
    }
    return out;
}

std::string GroundEnd::authorisation_problem() const {
    if (!driver_ || driver_->link_up()) {
        return {};
    }
    const auto& s = driver_->stats();
    if (s.frames_needing_key > 0) {
        return "not authorised: the vehicle authenticates its ground link and this end has no key "
               "(--key FILE, a copy of the vehicle's groundlink.key_file, /etc/airseg/ground.key on an "
               "installed vehicle)";
    }
    // A vehicle with a monitor key too sends its handshakes under each key in turn: one that does not verify
    // says little until several have come and none did.
    if (s.hellos_with_other_key >= 3 && s.hellos_received == 0) {
        return "not authorised: the vehicle's handshake does not verify with this key: it is not the "
               "vehicle's groundlink.key_file (nor its monitor_key_file)";
    }
    if (s.hellos_without_key > 0) {
        return "the vehicle's ground link has no key and this end has one (--key): no link; give the "
               "vehicle the same key (groundlink.key_file)";
    }
    return {};
}

bool GroundEnd::link_up() const {
    return driver_ && driver_->link_up();
}

std::uint64_t GroundEnd::bytes_sent() const {
    return driver_ ? driver_->stats().bytes_sent : 0;
}

// Input makes the transport poll, which sends a probe a path owes: the report, if it is due, goes first and
// stands in for the probe.
void GroundEnd::on_bytes(std::size_t path, std::span<const std::uint8_t> bytes) {
    send_report_if_due(SteadyClock::now());
    driver_->handle_bytes(path, bytes);
}

void GroundEnd::send_report_if_due(TimePoint now) {
    if (report_timing_.due(now, driver_->core())) {
        driver_->send_fast(proto::kPriorityStatus, proto::kTopicReception,
                           proto::encode(proto::ReceptionReport{pushed_received_}));
        report_timing_.sent(now);
    }
}

// At least once a second while the link is up: how many pushed telemetry messages arrived, so the vehicle
// can measure what the link delivers. When: reception_report_timing.hpp (it doubles as the keepalive).
void GroundEnd::do_report() {
    const TimePoint now = SteadyClock::now();
    send_report_if_due(now);
    const TimePoint next = report_timing_.next_check(now, driver_->core());
    report_timer_.expires_at(next);
    report_timer_.async_wait([this](boost::system::error_code ec) {
        if (!ec && !stopped_) {
            do_report();
        }
    });
}

void GroundEnd::on_delivered(gl::Delivered m) {
    auto decoded = proto::decode(m.bytes);
    if (!decoded.message) {
        return;
    }
    if (std::holds_alternative<proto::Telemetry>(*decoded.message) ||
        std::holds_alternative<proto::LinkStatsReport>(*decoded.message)) {
        ++pushed_received_;
    }
    if (handlers_.on_message) {
        handlers_.on_message(std::move(*decoded.message));
    }
}

}  // namespace airseg::groundside
