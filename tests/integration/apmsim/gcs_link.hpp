#pragma once
// A ground station on a real serial device (the simulator's pty), speaking MAVLink with the project codec,
// and a client for the simulator's control socket. Every wait is on a condition with a deadline.
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/autopilot/mavlink/parser.hpp"

namespace airseg::apmsim::test {

namespace mv = mavlink;
using RealClock = std::chrono::steady_clock;

struct Heard {
    RealClock::time_point at;
    mv::Frame frame;
};

class GcsLink {
  public:
    GcsLink() = default;
    ~GcsLink() { close(); }
    GcsLink(const GcsLink&) = delete;
    GcsLink& operator=(const GcsLink&) = delete;

    /// Opens the device as a ground station would (raw 8N1, no controlling terminal).
    bool open(const std::string& path) {
        fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
        if (fd_ < 0) {
            return false;
        }
        termios t{};
        if (::tcgetattr(fd_, &t) == 0) {
            ::cfmakeraw(&t);
            ::cfsetspeed(&t, B115200);
            ::tcsetattr(fd_, TCSANOW, &t);
        }
        opened_at_ = RealClock::now();
        return true;
    }
    void close() {
        if (fd_ >= 0) {
            ::close(fd_);
            fd_ = -1;
        }
    }
    bool is_open() const { return fd_ >= 0; }
    /// The MAVLink version of what this station sends (MAVLink 2 unless told).
    void set_version(mv::Version v) { encoder_.set_version(v); }
    RealClock::time_point opened_at() const { return opened_at_; }

    template <mv::Message M>
    bool send(M m) {
        if constexpr (requires { m.target_system; }) {
            if (m.target_system == 0) {
                m.target_system = 1;
                m.target_component = 1;
            }
        }
        const auto bytes = encoder_.encode(m);
        return ::write(fd_, bytes.data(), bytes.size()) == static_cast<ssize_t>(bytes.size());
    }

    /// Reads what is there, waiting up to `wait` for the first bytes. False when the link is gone (EOF/EIO).
    bool pump(std::chrono::milliseconds wait) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0) {
            return true;
        }
        std::uint8_t buf[4096];
        for (;;) {
            const ssize_t n = ::read(fd_, buf, sizeof buf);
            if (n > 0) {
                parser_.push(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(n)),
                             [&](const mv::Frame& f) {
                                 heard.push_back(Heard{RealClock::now(), f});
                             });
                continue;
            }
            if (n < 0 && errno == EAGAIN) {
                return true;
            }
            return false;  // 0 or EIO: the other side went away
        }
    }

    /// Index of the first frame at or after `from` satisfying `pred`, waiting up to `timeout`.
    std::optional<std::size_t> wait_frame(const std::function<bool(const mv::Frame&)>& pred,
                                          std::chrono::milliseconds timeout, std::size_t from) {
        const auto deadline = RealClock::now() + timeout;
        std::size_t scan = from;
        for (;;) {
            for (; scan < heard.size(); ++scan) {
                if (pred(heard[scan].frame)) {
                    return scan;
                }
            }
            if (RealClock::now() >= deadline || !pump(std::chrono::milliseconds(20))) {
                return std::nullopt;
            }
        }
    }
    template <mv::Message M>
    std::optional<M> wait_for(const std::function<bool(const M&)>& pred, std::chrono::milliseconds timeout,
                              std::size_t from, std::size_t* at = nullptr) {
        const auto i = wait_frame(
            [&](const mv::Frame& f) {
                auto m = mv::decode<M>(f);
                return m && pred(*m);
            },
            timeout, from);
        if (!i) {
            return std::nullopt;
        }
        if (at != nullptr) {
            *at = *i;
        }
        return mv::decode<M>(heard[*i].frame);
    }
    template <mv::Message M>
    std::optional<M> wait_for(std::chrono::milliseconds timeout, std::size_t from) {
        return wait_for<M>([](const M&) { return true; }, timeout, from);
    }
    template <mv::Message M>
    std::vector<M> all(std::size_t from = 0) const {
        std::vector<M> out;
        for (std::size_t i = from; i < heard.size(); ++i) {
            if (auto m = mv::decode<M>(heard[i].frame)) {
                out.push_back(*m);
            }
        }
        return out;
    }

    std::vector<Heard> heard;

  private:
    int fd_ = -1;
    RealClock::time_point opened_at_{};
    mv::Encoder encoder_{255, 190};
    mv::Parser parser_;
};

/// Datagram client of the simulator's control socket.
class ControlClient {
  public:
    ControlClient(std::string own_path, std::string server_path)
        : own_(std::move(own_path)), server_(std::move(server_path)) {
        fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::strncpy(a.sun_path, own_.c_str(), sizeof a.sun_path - 1);
        ::unlink(own_.c_str());
        ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    }
    ~ControlClient() {
        ::close(fd_);
        ::unlink(own_.c_str());
    }
    ControlClient(const ControlClient&) = delete;
    ControlClient& operator=(const ControlClient&) = delete;

    /// Sends one command and returns the reply, or nothing after `timeout`.
    std::optional<std::string> command(const std::string& text,
                                       std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::strncpy(a.sun_path, server_.c_str(), sizeof a.sun_path - 1);
        if (::sendto(fd_, text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a) < 0) {
            return std::nullopt;
        }
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) {
            return std::nullopt;
        }
        char buf[65536];
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n < 0) {
            return std::nullopt;
        }
        return std::string(buf, static_cast<std::size_t>(n));
    }

  private:
    std::string own_;
    std::string server_;
    int fd_ = -1;
};

}  // namespace airseg::apmsim::test
