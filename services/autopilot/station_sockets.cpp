#include "services/autopilot/station_sockets.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <deque>
#include <map>

#include "base/time.hpp"
#include "hal/udp_socket.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/parser.hpp"
#include "services/common/limited_log.hpp"

namespace airseg::autopilot {

namespace mav = airseg::mavlink;
using Tcp = asio::ip::tcp;

namespace {

constexpr auto kAcceptRetry = std::chrono::milliseconds(100);

/// The size of the frame starting at `bytes[at]` (frames re-encoded here: unsigned), or 0.
std::size_t frame_size(std::span<const std::uint8_t> bytes, std::size_t at) {
    if (at + 2 > bytes.size()) {
        return 0;
    }
    const std::size_t payload = bytes[at + 1];
    const std::size_t size = bytes[at] == mav::kMagicV2
                                 ? mav::kHeaderLengthV2 + payload + mav::kChecksumLength +
                                       ((bytes.size() > at + 2 && (bytes[at + 2] & mav::kIncompatSigned) != 0)
                                            ? mav::kSignatureLength
                                            : 0)
                                 : mav::kHeaderLengthV1 + payload + mav::kChecksumLength;
    return std::min(size, bytes.size() - at);
}

}  // namespace

class StationSockets::Impl : public std::enable_shared_from_this<Impl> {
  public:
    Impl(asio::any_io_executor strand, GcsEndpointConfig config, std::string name, std::size_t tcp_backlog,
         Handlers handlers)
        : strand_(strand),
          config_(std::move(config)),
          name_(std::move(name)),
          tcp_backlog_(tcp_backlog),
          handlers_(std::move(handlers)),
          udp_(strand),
          acceptor_(strand),
          retry_(strand) {}

    std::string start() {
        if (auto problems = config_.validate(); !problems.empty()) {
            return name_ + ": " + problems.front();
        }
        running_ = true;
        if (!config_.udp.empty()) {
            const auto bind = *parse_host_port(config_.udp);
            hal::UdpConfig u;
            u.bind_address = bind.host;
            u.bind_port = bind.port;
            if (auto r = udp_.open(u); !r.ok()) {
                stop();
                return name_ + ": " + r.message;
            }
            if (const auto remote = parse_host_port(config_.udp_remote)) {
                Peer& fixed =
                    peers_[hal::UdpSocket::Endpoint(asio::ip::make_address(remote->host), remote->port)];
                fixed.id = next_station_++;
                fixed.fixed = true;
            }
            udp_.start_receiving(
                // Weak: the socket keeps its handlers, and the socket is ours.
                [weak = weak_from_this()](std::span<const std::uint8_t> d,
                                          const hal::UdpSocket::Endpoint& from) {
                    if (auto self = weak.lock()) {
                        self->on_datagram(d, from);
                    }
                },
                [name = name_](std::error_code, const std::string& what) {
                    spdlog::warn("{}: {}", name, what);
                });
        }
        if (!config_.tcp.empty()) {
            const auto listen = *parse_host_port(config_.tcp);
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
                return name_ + ": cannot listen on tcp " + config_.tcp + ": " + ec.message();
            }
            accept();
        }
        return {};
    }

    void stop() {
        running_ = false;  // nothing more reaches the handlers: the owner may be gone once stop() returns
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

    std::vector<StationId> stations() {
        const auto now = SteadyClock::now();
        std::vector<StationId> out;
        for (auto it = peers_.begin(); it != peers_.end();) {
            if (!it->second.fixed && now - it->second.last_heard > kPeerTimeout) {
                const auto id = it->second.id;
                it = peers_.erase(it);
                tell_gone(id);
            } else {
                out.push_back(it->second.id);
                ++it;
            }
        }
        for (const auto& [id, client] : clients_) {
            out.push_back(id);
        }
        return out;
    }

    void send(StationId station, std::span<const std::uint8_t> frames) {
        if (!running_ || frames.empty()) {
            return;
        }
        if (auto client = clients_.find(station); client != clients_.end()) {
            send_tcp(client->second, frames);
            return;
        }
        for (const auto& [at, peer] : peers_) {
            if (peer.id == station) {
                send_udp(frames, at);
                return;
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
        StationId id = 0;
        mav::Parser parser;
        TimePoint last_heard{};
        bool fixed = false;  // the configured destination: never forgotten
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

    void tell_gone(StationId id) {
        if (running_ && handlers_.gone) {
            handlers_.gone(id);
        }
    }

    /// Whole frames in datagrams of at most kMaxDatagram bytes (one longer frame alone).
    void send_udp(std::span<const std::uint8_t> frames, const hal::UdpSocket::Endpoint& to) {
        std::size_t begin = 0;
        while (begin < frames.size()) {
            std::size_t end = begin;
            while (end < frames.size()) {
                const auto size = frame_size(frames, end);
                if (size == 0 || (end > begin && end + size - begin > kMaxDatagram)) {
                    break;
                }
                end += size;
            }
            if (end == begin) {
                end = frames.size();  // not a frame that can be measured: as it is
            }
            if (udp_.send_to({frames.begin() + static_cast<std::ptrdiff_t>(begin),
                              frames.begin() + static_cast<std::ptrdiff_t>(end)},
                             to) == hal::WriteResult::Queued) {
                stats_.bytes_out += end - begin;
            } else {
                ++stats_.dropped_out;
            }
            begin = end;
        }
    }

    void send_tcp(const std::shared_ptr<Client>& client, std::span<const std::uint8_t> frames) {
        if (client->backlog + frames.size() > tcp_backlog_) {
            ++stats_.dropped_out;
            return;
        }
        client->queue.emplace_back(frames.begin(), frames.end());
        client->backlog += frames.size();
        stats_.bytes_out += frames.size();
        if (!client->writing) {
            write(client);
        }
    }

    /// The valid frames among `bytes`, re-encoded, in order; counts the rest.
    std::vector<StationFrame> valid_frames(mav::Parser& parser, std::span<const std::uint8_t> bytes) {
        std::vector<StationFrame> out;
        const auto damaged_before = parser.stats().bad_checksum + parser.stats().truncated;
        parser.push(bytes, [&](const mav::Frame& f) {
            auto frame = f.checksum_verified ? mav::reencode(f) : std::vector<std::uint8_t>{};
            if (frame.empty()) {
                ++stats_.invalid_in;
                return;
            }
            ++stats_.frames_in;
            out.push_back(StationFrame{f, std::move(frame)});
        });
        stats_.invalid_in += parser.stats().bad_checksum + parser.stats().truncated - damaged_before;
        return out;
    }

    void on_datagram(std::span<const std::uint8_t> datagram, const hal::UdpSocket::Endpoint& from) {
        if (!running_) {
            return;
        }
        auto it = peers_.find(from);
        if (it == peers_.end()) {
            if (peers_.size() >= kMaxUdpPeers) {
                evict_stalest_peer();
            }
            it = peers_.try_emplace(from).first;
            it->second.id = next_station_++;
        }
        Peer& peer = it->second;
        peer.last_heard = SteadyClock::now();
        pass_on(peer.id, valid_frames(peer.parser, datagram));
    }

    void evict_stalest_peer() {
        auto stalest = peers_.end();
        for (auto p = peers_.begin(); p != peers_.end(); ++p) {
            if (!p->second.fixed &&
                (stalest == peers_.end() || p->second.last_heard < stalest->second.last_heard)) {
                stalest = p;
            }
        }
        if (stalest != peers_.end()) {
            const auto id = stalest->second.id;
            peers_.erase(stalest);
            ++stats_.udp_peers_evicted;
            tell_gone(id);
        }
    }

    void pass_on(StationId station, std::vector<StationFrame> frames) {
        if (running_ && !frames.empty() && handlers_.frames) {
            handlers_.frames(station, std::move(frames));
        }
    }

    void accept() {
        auto client = std::make_shared<Client>(strand_);
        acceptor_.async_accept(
            client->socket, [self = shared_from_this(), client](boost::system::error_code ec) {
                if (ec || !self->running_) {
                    if (ec != asio::error::operation_aborted && self->running_) {
                        // Out of descriptors, say: try again shortly, not in a spin.
                        self->log_.log(self->name_ + ": accept", SteadyClock::now(), spdlog::level::warn,
                                       "{}: accept: {}", self->name_, ec.message());
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
                    self->log_.log(self->name_ + ": refused a tcp client", SteadyClock::now(),
                                   spdlog::level::warn, "{}: refused a tcp client: {} already connected",
                                   self->name_, kMaxTcpClients);
                    boost::system::error_code ignored;
                    client->socket.close(ignored);
                    self->accept();
                    return;
                }
                boost::system::error_code ignored;
                client->socket.set_option(Tcp::no_delay(true), ignored);  // a station's answers are small
                const auto id = self->next_station_++;
                self->clients_.emplace(id, client);
                self->read(id, client);
                self->accept();
            });
    }

    void read(StationId id, const std::shared_ptr<Client>& client) {
        client->socket.async_read_some(
            asio::buffer(client->buffer),
            [self = shared_from_this(), id, client](boost::system::error_code ec, std::size_t n) {
                if (ec || !self->running_) {
                    self->drop(id);
                    return;
                }
                self->pass_on(id, self->valid_frames(client->parser, std::span(client->buffer).first(n)));
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

    void drop(StationId id) {
        if (auto it = clients_.find(id); it != clients_.end()) {
            boost::system::error_code ignored;
            it->second->socket.close(ignored);
            clients_.erase(it);
            tell_gone(id);
        }
    }

    asio::any_io_executor strand_;
    GcsEndpointConfig config_;
    std::string name_;
    std::size_t tcp_backlog_;
    Handlers handlers_;
    hal::UdpSocket udp_;
    Tcp::acceptor acceptor_;
    asio::steady_timer retry_;
    LimitedLog log_;
    std::map<hal::UdpSocket::Endpoint, Peer> peers_;
    std::map<StationId, std::shared_ptr<Client>> clients_;
    StationId next_station_ = 1;
    GcsEndpointStats stats_;
    bool running_ = false;
};

StationSockets::StationSockets(asio::any_io_executor strand, GcsEndpointConfig config, std::string name,
                               std::size_t tcp_backlog, Handlers handlers)
    : impl_(std::make_shared<Impl>(std::move(strand), std::move(config), std::move(name), tcp_backlog,
                                   std::move(handlers))) {}

StationSockets::~StationSockets() {
    impl_->stop();
}
std::string StationSockets::start() {
    return impl_->start();
}
void StationSockets::stop() {
    impl_->stop();
}
std::vector<StationId> StationSockets::stations() {
    return impl_->stations();
}
void StationSockets::send(StationId station, std::span<const std::uint8_t> frames) {
    impl_->send(station, frames);
}
std::uint16_t StationSockets::udp_port() const {
    return impl_->udp_port();
}
std::uint16_t StationSockets::tcp_port() const {
    return impl_->tcp_port();
}
GcsEndpointStats StationSockets::stats() const {
    return impl_->stats();
}

}  // namespace airseg::autopilot
