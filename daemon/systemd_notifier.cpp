#include "daemon/systemd_notifier.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>

namespace airseg::daemon {
namespace {

template <typename T>
std::optional<T> parse_number(const char* text) {
    if (text == nullptr) {
        return std::nullopt;
    }
    const std::string_view s(text);
    T value{};
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty()) {
        return std::nullopt;
    }
    return value;
}

}  // namespace

std::optional<std::chrono::microseconds> watchdog_period_from(const char* usec, const char* pid,
                                                              long own_pid) {
    const auto period = parse_number<unsigned long long>(usec);
    if (!period || *period == 0) {
        return std::nullopt;
    }
    if (pid != nullptr) {
        const auto target = parse_number<long>(pid);
        if (!target || *target != own_pid) {
            return std::nullopt;
        }
    }
    return std::chrono::microseconds(static_cast<std::chrono::microseconds::rep>(*period));
}

SystemdNotifier::SystemdNotifier() {
    watchdog_ = watchdog_period_from(std::getenv("WATCHDOG_USEC"), std::getenv("WATCHDOG_PID"), getpid());
    const char* socket_name = std::getenv("NOTIFY_SOCKET");
    if (socket_name == nullptr || *socket_name == '\0') {
        return;
    }
    const std::string_view name(socket_name);
    // A path, or '@' for Linux's abstract namespace (the name then starts with a NUL byte).
    if ((name.front() != '/' && name.front() != '@') || name.size() >= sizeof(address_.sun_path)) {
        spdlog::warn("systemd: NOTIFY_SOCKET '{}' is not a socket path or abstract name; not notifying",
                     name);
        return;
    }
    address_.sun_family = AF_UNIX;
    std::memcpy(address_.sun_path, name.data(), name.size());
    if (name.front() == '@') {
        address_.sun_path[0] = '\0';
    }
    address_length_ =
        static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size() + (name.front() == '/' ? 1 : 0));
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) {
        spdlog::warn("systemd: cannot open a socket for NOTIFY_SOCKET: {}", std::strerror(errno));
    }
}

SystemdNotifier::~SystemdNotifier() {
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

bool SystemdNotifier::try_send(std::string_view state) {
    const auto sent = ::sendto(fd_, state.data(), state.size(), MSG_NOSIGNAL | MSG_DONTWAIT,
                               reinterpret_cast<const sockaddr*>(&address_), address_length_);
    if (sent >= 0) {
        return true;
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK) {
        return false;
    }
    spdlog::debug("systemd: notify failed: {}", std::strerror(errno));
    return true;  // nobody listens: trying again would not help
}

void SystemdNotifier::send(std::string_view state, bool must_arrive) {
    if (fd_ < 0) {
        return;
    }
    while (!unsent_.empty() && try_send(unsent_.front())) {
        unsent_.pop_front();
    }
    if (unsent_.empty() && try_send(state)) {
        return;
    }
    if (must_arrive) {
        unsent_.emplace_back(state);
    } else {
        spdlog::debug("systemd: notify socket full; {} dropped", state.substr(0, state.find('=')));
    }
}

void SystemdNotifier::ready() {
    send("READY=1", true);
}

void SystemdNotifier::status(const std::string& line) {
    send("STATUS=" + line, false);
}

void SystemdNotifier::watchdog() {
    send("WATCHDOG=1", false);
}

void SystemdNotifier::stopping() {
    send("STOPPING=1", true);
}

void SystemdNotifier::reloading() {
    send("RELOADING=1", true);
}

}  // namespace airseg::daemon
