#pragma once
// The on-board command socket: a Unix stream socket speaking newline-delimited JSON. Each line is one request
// ({"cmd":"status"}, {"cmd":"param.get","name":"WP_RADIUS"}, ...) answered by one line, in order. Requests go
// through the shared CommandDispatcher with the control role: whoever can open the socket (mode 0660, group
// airseg) is on the board and trusted.
//
// Bounds (docs/reliability.md, "Bounds and caps"), each counted in stats():
// - a request line is at most kMaxRequestBytes; a longer one is answered bad_request and the client closed;
// - answers waiting for a client that does not read are at most kMaxQueuedBytes: a client whose queue would
//   pass it is closed (closed_slow), and its memory freed;
// - a client with no request running that sends no whole request and takes none of its answers for
//   kIdleTimeout is closed (closed_idle);
// - at most kMaxConnections at once: a new client when the table is full takes the place of the client idle
//   longest (evicted); only when every client has a request running is it refused with one error line
//   (refused).
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "base/time.hpp"
#include "services/common/asio.hpp"
#include "services/common/command_dispatcher.hpp"
#include "services/common/limited_log.hpp"

namespace airseg::status {

struct LocalSocketStats {
    std::size_t clients = 0;        // open now
    std::uint64_t accepted = 0;     // connections taken, ever
    std::uint64_t refused = 0;      // turned away: every place taken by a client with a request running
    std::uint64_t evicted = 0;      // idle clients closed to make room for a new one
    std::uint64_t closed_slow = 0;  // closed: answers not read past kMaxQueuedBytes
    std::uint64_t closed_idle = 0;  // closed: nothing from or to them for kIdleTimeout
};

class LocalCommandServer {
  public:
    static constexpr std::size_t kMaxRequestBytes = 1 << 20;  // a flight plan travels inline
    static constexpr std::size_t kMaxConnections = 16;
    static constexpr std::size_t kMaxQueuedBytes = 256 * 1024;
    static constexpr Duration kIdleTimeout = seconds(30);

    LocalCommandServer(Strand strand, const CommandDispatcher& dispatcher,
                       Duration idle_timeout = kIdleTimeout);
    ~LocalCommandServer();

    /// Binds `path` (creating its directory, replacing a stale socket) with `mode`. Returns an error message.
    std::string open(const std::string& path, unsigned mode);
    void close();
    bool is_open() const { return acceptor_.is_open(); }
    std::size_t connections() const { return sessions_.size(); }
    /// Counters (call on the strand).
    LocalSocketStats stats() const;
    /// Summaries of log floods that have stopped (call on the strand, now and then).
    void flush_log(TimePoint now) { log_.flush(now); }

  private:
    class Session;
    void do_accept();
    void admit(asio::local::stream_protocol::socket socket);

    Strand strand_;
    const CommandDispatcher& dispatcher_;
    Duration idle_timeout_;
    asio::local::stream_protocol::acceptor acceptor_;
    std::string path_;
    std::set<std::shared_ptr<Session>> sessions_;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
    LocalSocketStats stats_;
    LimitedLog log_;
};

}  // namespace airseg::status
