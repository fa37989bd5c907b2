#pragma once
// One client of the ground hub on a stream socket (Unix or TCP): reads hub frames, queues writes (one in
// flight), and closes with a reason it sends first. A client that stops reading is dropped once its queue
// passes a bound, so one stuck watcher cannot grow the hub's memory or hold the others back.
#include <boost/asio/generic/stream_protocol.hpp>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "groundside/hub_wire.hpp"
#include "services/common/asio.hpp"

namespace airseg::ground {

class ClientConnection : public std::enable_shared_from_this<ClientConnection> {
  public:
    using Socket = asio::generic::stream_protocol::socket;
    struct Handlers {
        std::function<void(ClientConnection&, groundside::hub::Frame)> on_frame;
        std::function<void(ClientConnection&, const std::string& why)> on_closed;
    };
    /// Bytes queued for a client beyond which it counts as stuck.
    static constexpr std::size_t kMaxQueued = 4 << 20;

    ClientConnection(Socket socket, std::uint32_t id, std::string peer, Handlers handlers);

    void start();
    void send(std::vector<std::uint8_t> frame);
    /// Sends {"error": why} (best effort) and closes; on_closed runs once.
    void close(const std::string& why);

    std::uint32_t id() const { return id_; }
    const std::string& peer() const { return peer_; }
    bool open() const { return !closed_; }

  private:
    void read();
    void write_next();
    void finish(const std::string& why);

    Socket socket_;
    std::uint32_t id_;
    std::string peer_;
    Handlers handlers_;
    groundside::hub::FrameReader reader_;
    std::array<std::uint8_t, 16384> buffer_{};
    std::deque<std::vector<std::uint8_t>> queue_;
    std::size_t queued_bytes_ = 0;
    bool writing_ = false;
    bool closing_ = false;
    bool closed_ = false;
    std::string close_reason_;
};

}  // namespace airseg::ground
