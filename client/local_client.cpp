#include "client/local_client.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace airseg::client {

namespace {
constexpr std::size_t kMaxAnswerBytes = 16 << 20;
}

LocalClient::LocalClient(std::string socket_path, std::chrono::milliseconds timeout)
    : path_(std::move(socket_path)), timeout_(timeout) {}

LocalClient::~LocalClient() {
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

bool LocalClient::connect(std::string& error) {
    if (fd_ >= 0) {
        return true;
    }
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path_.size() >= sizeof(addr.sun_path)) {
        error = "socket path too long: " + path_;
        return false;
    }
    std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) {
        error = std::string("socket: ") + std::strerror(errno);
        return false;
    }
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        error = "cannot connect to " + path_ + ": " + std::strerror(errno) + " (is airsegd running?)";
        ::close(fd_);
        fd_ = -1;
        return false;
    }
    return true;
}

// airsegd closes a connection left idle (docs/status.md): a kept connection it has closed is opened again
// before the request goes, so a slow watcher never sees that.
bool LocalClient::closed_by_daemon() const {
    if (fd_ < 0 || !pending_.empty()) {
        return false;
    }
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0) {
        return false;
    }
    char byte = 0;
    return ::recv(fd_, &byte, 1, MSG_PEEK | MSG_DONTWAIT) == 0 || (p.revents & (POLLHUP | POLLERR)) != 0;
}

LocalAnswer LocalClient::request(const nlohmann::json& request) {
    LocalAnswer out;
    if (closed_by_daemon()) {
        ::close(fd_);
        fd_ = -1;
    }
    if (!connect(out.error)) {
        return out;
    }
    std::string line;
    try {
        line = request.dump() + "\n";
    } catch (const nlohmann::json::type_error&) {
        // A word of the command line that is not UTF-8 (a plan element's name, a parameter's): refused here,
        // as the daemon would refuse it.
        out.error = "the request holds text that is not valid UTF-8";
        return out;
    }
    std::size_t sent = 0;
    while (sent < line.size()) {
        const ssize_t n = ::send(fd_, line.data() + sent, line.size() - sent, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            out.error = std::string("send to ") + path_ + ": " + std::strerror(errno);
            return out;
        }
        sent += static_cast<std::size_t>(n);
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout_;
    for (;;) {
        if (auto nl = pending_.find('\n'); nl != std::string::npos) {
            auto answer = nlohmann::json::parse(pending_.substr(0, nl), nullptr, false);
            pending_.erase(0, nl + 1);
            if (answer.is_discarded()) {
                out.error = "airsegd answered something that is not JSON";
            } else {
                out.answer = std::move(answer);
            }
            return out;
        }
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) {
            out.error = "no answer from airsegd within " + std::to_string(timeout_.count()) + " ms";
            return out;
        }
        pollfd p{fd_, POLLIN, 0};
        const int r = ::poll(&p, 1, static_cast<int>(left.count()));
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r <= 0) {
            continue;  // the deadline check above ends the wait
        }
        char buf[65536];
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n <= 0) {
            out.error = "airsegd closed the connection";
            ::close(fd_);
            fd_ = -1;
            return out;
        }
        pending_.append(buf, static_cast<std::size_t>(n));
        if (pending_.size() > kMaxAnswerBytes) {
            out.error = "answer from airsegd larger than 16 MiB";
            return out;
        }
    }
}

}  // namespace airseg::client
