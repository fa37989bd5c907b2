#pragma once
// A Unix datagram socket that takes one text command per datagram and answers the sender (when the sender
// bound an address of its own) with one text reply. The simulators use it for fault injection while they run:
//   socat - UNIX-SENDTO:/tmp/linksim.ctl,bind=/tmp/me.sock   or any datagram client.
#include <functional>
#include <memory>
#include <string>
#include <system_error>

#include "hal/asio.hpp"

namespace airseg::toolcommon {

class ControlSocket {
  public:
    /// Returns the reply to send back.
    using Handler = std::function<std::string(const std::string& command)>;

    static constexpr std::size_t kMaxDatagram = 4096;

    ControlSocket(hal::Executor executor, std::string path, Handler handler);
    ~ControlSocket();  ///< closes the socket and removes its path
    ControlSocket(const ControlSocket&) = delete;
    ControlSocket& operator=(const ControlSocket&) = delete;

    /// Binds `path` (replacing a stale socket there, never another kind of file) and starts receiving.
    /// The error names the path and what failed.
    std::error_code open(std::string& message);
    const std::string& path() const { return path_; }

  private:
    struct State;
    std::shared_ptr<State> state_;
    std::string path_;
};

}  // namespace airseg::toolcommon
