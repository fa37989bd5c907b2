#include "services/autopilot/gcs_endpoint.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <deque>
#include <map>
#include <optional>

#include "hal/udp_socket.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "services/common/limited_log.hpp"

namespace airseg::autopilot {

namespace mav = airseg::mavlink;
using Tcp = asio::ip::tcp;

namespace {

constexpr auto kAcceptRetry = std::chrono::milliseconds(100);

struct HostPort {
    std::string host;
    std::uint16_t port = 0;
};

/// "ADDRESS:PORT" (the address an IP address, the port 0..65535), or nothing.
std::optional<HostPort> host_port(const std::string& text) {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == text.size() || colon + 6 < text.size()) {
        return std::nullopt;
    }
    unsigned long port = 0;
    for (char ch : text.substr(colon + 1)) {
        if (ch < '0' || ch > '9') {
            return std::nullopt;
        }
        port = port * 10 + static_cast<unsigned long>(ch - '0');
    }
    boost::system::error_code ec;
    asio::ip::make_address(text.substr(0, colon), ec);
    if (ec || port > 65535) {
        return std::nullopt;
    }
    return HostPort{text.substr(0, colon), static_cast<std::uint16_t>(port)};
}

/// The whole valid frames among `bytes`, re-encoded, in order; counts the rest.
std::vector<std::uint8_t> valid_frames(mav::Parser& parser, std::span<const std::uint8_t> bytes,
                                       GcsEndpointStats& stats) {
    std::vector<std::uint8_t> out;
    const auto damaged_before = parser.stats().bad_checksum + parser.stats().truncated;
    parser.push(bytes, [&](const mav::Frame& f) {
        const auto frame = f.checksum_verified ? mav::reencode(f) : std::vector<std::uint8_t>{};
        if (frame.empty()) {
            ++stats.invalid_in;
            return;
        }
        ++stats.frames_in;
        out.insert(out.end(), frame.begin(), frame.end());
    });
    stats.invalid_in += parser.stats().bad_checksum + parser.stats().truncated - damaged_before;
    return out;
}

}  // namespace

std::vector<std::string> GcsEndpointConfig::validate() const {
    std::vector<std::string> problems;
    if (!udp.empty() && !host_port(udp)) {
        problems.push_back("udp: \"" + udp + "\" is not ADDRESS:PORT (an IP address and a port 0..65535)");
    }
    if (!tcp.empty() && !host_port(tcp)) {
        problems.push_back("tcp: \"" + tcp + "\" is not ADDRESS:PORT (an IP address and a port 0..65535)");
    }
    if (!udp_remote.empty()) {
        const auto r = host_port(udp_remote);
        if (!r || r->port == 0) {
            problems.push_back("udp_remote: \"" + udp_remote + "\" is not ADDRESS:PORT with a port 1..65535");
        }
        if (udp.empty()) {
            problems.push_back("udp_remote: needs udp");
        }
    }
    return problems;
}

class GcsEndpoint::Impl : public std::enable_shared_from_this<Impl> {
  public:
    Impl(asio::any_io_executor strand, GcsEndpointConfig config, ToVehicle to_vehicle)
        : strand_(strand),
          config_(std::move(config)),
          to_vehicle_(std::move(to_vehicle)),
          udp_(strand),
          acceptor_(strand),
          retry_(strand) {}

    std::string start() {
        if (auto problems = config_.validate(); !problems.empty()) {
            return "gcs endpoint: " + problems.front();
        }
        running_ = true;
        if (!config_.udp.empty()) {
            const auto bind = *host_port(config_.udp);
            hal::UdpConfig u;
            u.bind_address = bind.host;
            u.bind_port = bind.port;
            if (const auto remote = host_port(config_.udp_remote)) {
                u.remote_address = remote->host;
                u.remote_port = remote->port;
            }
            if (auto r = udp_.open(u); !r.ok()) {
                stop();
                return "gcs endpoint: " + r.message;
            }
            udp_.start_receiving(
                // Weak: the socket keeps its handlers, and the socket is ours.
                [weak = weak_from_this()](std::span<const std::uint8_t> d,
                                          const hal::UdpSocket::Endpoint& from) {
                    if (auto self = weak.lock()) {
                        self->on_datagram(d, from);
                    }
                },
                [](std::error_code, const std::string& what) { spdlog::warn("gcs endpoint: {}", what); });
        }
        if (!config_.tcp.empty()) {
            const auto listen = *host_port(config_.tcp);
            const Tcp::endpoint at(asio::ip::make_address(listen.host), listen.port);
            boost::system::error_code ec;
            acceptor_.open(at.protocol(), ec);
            if (!ec) {
                acceptor_.set_option(Tcp::acceptor::reuse_address(true), ec);
                acceptor_.bind(at, ec);
            }
            if (!ec) {
                acceptor_.listen(asio::socket_base::max_listen_connections, ec);
            }
            if (ec) {
                stop();
                return "gcs endpoint: cannot listen on tcp " + config_.tcp + ": " + ec.message();
            }
            accept();
        }
        spdlog::info("gcs endpoint: MAVLink for ground stations on{}{}",
                     config_.udp.empty() ? "" : " udp port " + std::to_string(udp_port()),
                     config_.tcp.empty() ? "" : " tcp port " + std::to_string(tcp_port()));
        return {};
    }

    void stop() {
        running_ = false;
        udp_.close();
        boost::system::error_code ignored;
        acceptor_.close(ignored);
        retry_.cancel();
        for (auto& [id, client] : clients_) {
            client->socket.close(ignored);
        }
        clients_.clear();
        peers_.clear();
    }

    void from_vehicle(std::span<const std::uint8_t> frames) {
        if (!running_ || frames.empty()) {
            return;
        }
        const auto now = SteadyClock::now();
        if (udp_.is_open()) {
            for (auto it = peers_.begin(); it != peers_.end();) {
                if (now - it->second.last_heard > kPeerTimeout) {
                    it = peers_.erase(it);
                    continue;
                }
                send_udp(frames, it->first);
                ++it;
            }
            if (const auto remote = udp_.remote(); remote && !peers_.contains(*remote) && fixed_remote()) {
                send_udp(frames, *remote);
            }
        }
        for (auto& [id, client] : clients_) {
            if (client->backlog + frames.size() > kMaxTcpBacklog) {
                ++stats_.dropped_out;
                continue;
            }
            client->queue.emplace_back(frames.begin(), frames.end());
            client->backlog += frames.size();
            stats_.bytes_out += frames.size();
            if (!client->writing) {
                write(client);
            }
        }
    }

    std::uint16_t udp_port() const { return udp_.is_open() ? udp_.local_endpoint().port() : 0; }
    std::uint16_t tcp_port() const {
        boost::system::error_code ec;
        return acceptor_.is_open() ? acceptor_.local_endpoint(ec).port() : 0;
    }
    GcsEndpointStats stats() const {
        GcsEndpointStats s = stats_;
        s.udp_peers = peers_.size();
        s.tcp_clients = clients_.size();
        return s;
    }

  private:
    struct Peer {
        mav::Parser parser;
        TimePoint last_heard{};
    };
    struct Client {
        explicit Client(asio::any_io_executor ex) : socket(ex) {}
        Tcp::socket socket;
        mav::Parser parser;
        std::array<std::uint8_t, 2048> buffer{};
        std::deque<std::vector<std::uint8_t>> queue;
        std::size_t backlog = 0;
        bool writing = false;
    };

    bool fixed_remote() const { return !config_.udp_remote.empty(); }

    void send_udp(std::span<const std::uint8_t> frames, const hal::UdpSocket::Endpoint& to) {
        if (udp_.send_to({frames.begin(), frames.end()}, to) == hal::WriteResult::Queued) {
            stats_.bytes_out += frames.size();
        } else {
            ++stats_.dropped_out;
        }
    }

    void on_datagram(std::span<const std::uint8_t> datagram, const hal::UdpSocket::Endpoint& from) {
        if (!running_) {
            return;
        }
        auto it = peers_.find(from);
        if (it == peers_.end()) {
            if (peers_.size() >= kMaxUdpPeers) {
                const auto stalest = std::min_element(
                    peers_.begin(), peers_.end(),
                    [](const auto& a, const auto& b) { return a.second.last_heard < b.second.last_heard; });
                peers_.erase(stalest);
                ++stats_.udp_peers_evicted;
            }
            it = peers_.try_emplace(from).first;
        }
        Peer& peer = it->second;
        peer.last_heard = SteadyClock::now();
        pass_on(valid_frames(peer.parser, datagram, stats_));
    }

    void pass_on(std::vector<std::uint8_t> frames) {
        if (!frames.empty() && to_vehicle_) {
            to_vehicle_(std::move(frames));
        }
    }

    void accept() {
        auto client = std::make_shared<Client>(strand_);
        acceptor_.async_accept(client->socket, [self = shared_from_this(),
                                                client](boost::system::error_code ec) {
            if (ec || !self->running_) {
                if (ec != asio::error::operation_aborted && self->running_) {
                    // Out of descriptors, say: try again shortly, not in a spin.
                    self->log_.log("gcs endpoint: accept", SteadyClock::now(), spdlog::level::warn,
                                   "gcs endpoint: accept: {}", ec.message());
                    self->retry_.expires_after(kAcceptRetry);
                    self->retry_.async_wait([self](boost::system::error_code e) {
                        if (!e && self->running_) {
                            self->accept();
                        }
                    });
                }
                return;
            }
            if (self->clients_.size() >= kMaxTcpClients) {
                ++self->stats_.tcp_refused;
                self->log_.log("gcs endpoint: refused a tcp client", SteadyClock::now(), spdlog::level::warn,
                               "gcs endpoint: refused a tcp client: {} already connected", kMaxTcpClients);
                boost::system::error_code ignored;
                client->socket.close(ignored);
                self->accept();
                return;
            }
            const auto id = self->next_client_++;
            self->clients_.emplace(id, client);
            self->read(id, client);
            self->accept();
        });
    }

    void read(std::uint64_t id, const std::shared_ptr<Client>& client) {
        client->socket.async_read_some(
            asio::buffer(client->buffer),
            [self = shared_from_this(), id, client](boost::system::error_code ec, std::size_t n) {
                if (ec || !self->running_) {
                    self->drop(id);
                    return;
                }
                self->pass_on(valid_frames(client->parser, std::span(client->buffer).first(n), self->stats_));
                self->read(id, client);
            });
    }

    void write(const std::shared_ptr<Client>& client) {
        client->writing = true;
        asio::async_write(client->socket, asio::buffer(client->queue.front()),
                          [self = shared_from_this(), client](boost::system::error_code ec, std::size_t) {
                              client->writing = false;
                              if (ec) {
                                  return;  // the read side notices and drops the client
                              }
                              client->backlog -= client->queue.front().size();
                              client->queue.pop_front();
                              if (!client->queue.empty()) {
                                  self->write(client);
                              }
                          });
    }

    void drop(std::uint64_t id) {
        if (auto it = clients_.find(id); it != clients_.end()) {
            boost::system::error_code ignored;
            it->second->socket.close(ignored);
            clients_.erase(it);
        }
    }

    asio::any_io_executor strand_;
    GcsEndpointConfig config_;
    ToVehicle to_vehicle_;
    hal::UdpSocket udp_;
    Tcp::acceptor acceptor_;
    asio::steady_timer retry_;
    LimitedLog log_;
    std::map<hal::UdpSocket::Endpoint, Peer> peers_;
    std::map<std::uint64_t, std::shared_ptr<Client>> clients_;
    std::uint64_t next_client_ = 0;
    GcsEndpointStats stats_;
    bool running_ = false;
};

GcsEndpoint::GcsEndpoint(asio::any_io_executor strand, GcsEndpointConfig config, ToVehicle to_vehicle)
    : impl_(std::make_shared<Impl>(std::move(strand), std::move(config), std::move(to_vehicle))) {}

GcsEndpoint::~GcsEndpoint() {
    impl_->stop();
}

std::string GcsEndpoint::start() {
    return impl_->start();
}
void GcsEndpoint::stop() {
    impl_->stop();
}
void GcsEndpoint::from_vehicle(std::span<const std::uint8_t> frames) {
    impl_->from_vehicle(frames);
}
std::uint16_t GcsEndpoint::udp_port() const {
    return impl_->udp_port();
}
std::uint16_t GcsEndpoint::tcp_port() const {
    return impl_->tcp_port();
}
GcsEndpointStats GcsEndpoint::stats() const {
    return impl_->stats();
}

}  // namespace airseg::autopilot
