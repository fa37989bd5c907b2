#include "client/radio_client.hpp"

#include <fmt/format.h>

#include <deque>
#include <random>
#include <sstream>

#include "hal/serial_port.hpp"
#include "hal/udp_socket.hpp"
#include "services/groundlink/link/key_file.hpp"
#include "services/groundlink/link/link_driver.hpp"

namespace airseg::client {

namespace gl = airseg::groundlink;
namespace proto = airseg::groundlink::protocol;

std::string validate(const RadioOptions& o) {
    if (!o.udp.empty()) {
        if (!o.ports.empty()) {
            return "--udp and --link exclude each other";
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

class RadioClient::Impl {
  public:
    explicit Impl(RadioOptions options)
        : options_(std::move(options)), strand_(asio::make_strand(io_)), report_timer_(strand_) {
        std::random_device rd;
        next_id_ = rd();  // answers left over from another client's session are not mistaken for ours
    }

    std::string open() {
        gl::TransportConfig t;
        if (!options_.udp.empty()) {
            t.half_duplex = false;
            t.link_rate_bytes_per_s = 1e6;
        } else {
            t.link_rate_bytes_per_s = options_.baud / 10.0;
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
        }
        std::random_device rd;
        t.boot_nonce = (static_cast<std::uint64_t>(rd()) << 32) | rd() | 1;
        driver_ = std::make_unique<gl::LinkDriver>(
            strand_, t,
            gl::LinkDriver::Handlers{[this](gl::Delivered m) { on_delivered(std::move(m)); },
                                     [this](const gl::TransportEvent& e) {
                                         if (e.kind == gl::TransportEvent::Kind::SessionEstablished ||
                                             e.kind == gl::TransportEvent::Kind::PeerRestarted) {
                                             pushed_received_ = 0;  // the vehicle counts per session too
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
            udp_->start_receiving([this](std::span<const std::uint8_t> d,
                                         const hal::UdpSocket::Endpoint&) { driver_->handle_bytes(0, d); },
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
            port->start_reading([this, i](std::span<const std::uint8_t> b) { driver_->handle_bytes(i, b); },
                                [this, i](std::error_code, const std::string& what) {
                                    port_errors_.push_back(what);
                                    driver_->set_writer(i, {});
                                });
            auto* raw = port.get();
            ports_.push_back(std::move(port));
            driver_->set_writer(i, [raw](std::vector<std::uint8_t> f) {
                return raw->write(std::move(f)) == hal::WriteResult::Queued;
            });
        }
        return {};
    }

    LocalAnswer request(const nlohmann::json& req, std::chrono::milliseconds timeout) {
        LocalAnswer out;
        const std::uint32_t id = next_id_++;
        std::optional<nlohmann::json> answer;
        awaiting_ = id;
        answer_ = &answer;
        std::optional<std::string> not_sent;
        asio::dispatch(strand_, [this, id, req, &not_sent] {
            const auto bytes = proto::encode(proto::Command{id, req});
            const auto r = driver_->send_safe(proto::kPriorityControl, bytes);
            if (r == gl::SendResult::TooLarge) {
                not_sent = fmt::format(
                    "the command is {} bytes, more than the link carries in one message ({} "
                    "bytes); not sent",
                    bytes.size(), driver_->core().config().max_message_size);
            } else if (r != gl::SendResult::Accepted) {
                not_sent =
                    fmt::format("the command could not be queued ({})", (std::ostringstream{} << r).str());
            }
        });
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (!answer && !not_sent && std::chrono::steady_clock::now() < deadline) {
            io_.run_for(std::chrono::milliseconds(20));
            if (io_.stopped()) {
                io_.restart();
            }
        }
        answer_ = nullptr;
        if (not_sent) {
            // Refused here, before the air: answered as the vehicle answers a request it cannot take.
            out.answer = nlohmann::json{{"ok", false}, {"status", "bad_request"}, {"error", *not_sent}};
            return out;
        }
        if (!answer) {
            out.error = fmt::format("no answer from the vehicle within {} ms ({})", timeout.count(),
                                    driver_->link_up() ? "link up" : "no link");
            return out;
        }
        // Let our acknowledgement of the answer reach the vehicle before the caller exits.
        io_.run_for(std::chrono::milliseconds(300));
        io_.restart();
        out.answer = std::move(answer);
        return out;
    }

    void run_for(std::chrono::milliseconds d, const std::function<void(const proto::Message&)>& on_message) {
        on_message_ = on_message;
        io_.run_for(d);
        io_.restart();
        on_message_ = nullptr;
    }

    nlohmann::json link_stats() const {
        const auto& s = driver_->stats();
        return {{"link", driver_->link_up() ? "up" : "down"},
                {"rtt_ms", std::round(s.srtt_ms)},
                {"loss", std::round(s.frame_loss * 1000) / 1000},
                {"frames_sent", s.frames_sent},
                {"frames_received", s.frames_received},
                {"crc_errors", s.crc_errors},
                {"mac_failures", s.mac_failures},
                {"authenticated", s.authenticated}};
    }

    bool link_up() const { return driver_->link_up(); }
    std::uint64_t bytes_sent() const { return driver_->stats().bytes_sent; }

    void send_joystick(double steering, double throttle) {
        asio::dispatch(strand_, [this, steering, throttle] {
            driver_->send_fast(proto::kPriorityControl, proto::kTopicJoystick,
                               proto::encode(proto::Joystick{steering, throttle}));
        });
    }

  private:
    /// Once a second while the link is up: how many pushed telemetry messages arrived, so the vehicle can
    /// measure what the link delivers.
    void do_report() {
        if (driver_->link_up()) {
            driver_->send_fast(proto::kPriorityStatus, proto::kTopicReception,
                               proto::encode(proto::ReceptionReport{pushed_received_}));
        }
        report_timer_.expires_after(std::chrono::seconds(1));
        report_timer_.async_wait([this](boost::system::error_code ec) {
            if (!ec) {
                do_report();
            }
        });
    }

    void on_delivered(gl::Delivered m) {
        auto decoded = proto::decode(m.bytes);
        if (!decoded.message) {
            return;
        }
        if (std::holds_alternative<proto::Telemetry>(*decoded.message) ||
            std::holds_alternative<proto::LinkStatsReport>(*decoded.message)) {
            ++pushed_received_;
        }
        if (auto* result = std::get_if<proto::Result>(&*decoded.message)) {
            if (answer_ != nullptr && result->request_id == awaiting_) {
                *answer_ = result->answer;
            }
            return;
        }
        if (on_message_) {
            on_message_(*decoded.message);
        }
    }

    RadioOptions options_;
    asio::io_context io_;
    Strand strand_;
    std::unique_ptr<gl::LinkDriver> driver_;
    std::vector<std::unique_ptr<hal::SerialPort>> ports_;
    std::unique_ptr<hal::UdpSocket> udp_;
    std::vector<std::string> port_errors_;
    std::uint32_t next_id_ = 1;
    std::uint32_t awaiting_ = 0;
    std::optional<nlohmann::json>* answer_ = nullptr;
    std::function<void(const proto::Message&)> on_message_;
    asio::steady_timer report_timer_;
    std::uint32_t pushed_received_ = 0;
};

RadioClient::RadioClient(RadioOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
RadioClient::~RadioClient() = default;
std::string RadioClient::open() {
    return impl_->open();
}
LocalAnswer RadioClient::request(const nlohmann::json& r, std::chrono::milliseconds t) {
    return impl_->request(r, t);
}
void RadioClient::run_for(std::chrono::milliseconds d, const std::function<void(const proto::Message&)>& f) {
    impl_->run_for(d, f);
}
nlohmann::json RadioClient::link_stats() const {
    return impl_->link_stats();
}
bool RadioClient::link_up() const {
    return impl_->link_up();
}
void RadioClient::send_joystick(double steering, double throttle) {
    impl_->send_joystick(steering, throttle);
}
std::uint64_t RadioClient::bytes_sent() const {
    return impl_->bytes_sent();
}

}  // namespace airseg::client
