#pragma once
// The on-board command socket: a Unix stream socket speaking newline-delimited JSON. Each line is one request
// ({"cmd":"status"}, {"cmd":"param.get","name":"WP_RADIUS"}, ...) answered by one line, in order. Requests go
// through the shared CommandDispatcher with the control role: whoever can open the socket (mode 0660, group
// airseg) is on the board and trusted.
#include <memory>
#include <set>
#include <string>

#include "services/common/asio.hpp"
#include "services/common/command_dispatcher.hpp"

namespace airseg::status {

class LocalCommandServer {
  public:
    static constexpr std::size_t kMaxRequestBytes = 1 << 20;  // a flight plan travels inline
    static constexpr std::size_t kMaxConnections = 16;

    LocalCommandServer(Strand strand, const CommandDispatcher& dispatcher);
    ~LocalCommandServer();

    /// Binds `path` (creating its directory, replacing a stale socket) with `mode`. Returns an error message.
    std::string open(const std::string& path, unsigned mode);
    void close();
    bool is_open() const { return acceptor_.is_open(); }
    std::size_t connections() const { return sessions_.size(); }

  private:
    class Session;
    void do_accept();

    Strand strand_;
    const CommandDispatcher& dispatcher_;
    asio::local::stream_protocol::acceptor acceptor_;
    std::string path_;
    std::set<std::shared_ptr<Session>> sessions_;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace airseg::status
