#include "client/hub_client.hpp"

#include <fmt/format.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <thread>

#include "services/groundlink/link/key_file.hpp"

namespace airseg::client {

namespace hub = groundside::hub;
namespace proto = groundlink::protocol;
using Clock = std::chrono::steady_clock;

namespace {

int connect_unix(const std::string& path, std::string& error) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof(addr.sun_path)) {
        error = "socket path too long: " + path;
        return -1;
    }
    std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        error = "cannot connect to the ground hub at " + path + ": " + std::strerror(errno) +
                " (is airseg-ground running?)";
        if (fd >= 0) {
            ::close(fd);
        }
        return -1;
    }
    return fd;
}

int connect_tcp(const std::string& host_port, std::string& error) {
    const auto colon = host_port.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == host_port.size()) {
        error = "--ground-tcp needs HOST:PORT, got '" + host_port + "'";
        return -1;
    }
    const auto host = host_port.substr(0, colon);
    const auto port = host_port.substr(colon + 1);
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    if (const int r = ::getaddrinfo(host.c_str(), port.c_str(), &hints, &found); r != 0) {
        error = "cannot resolve " + host_port + ": " + ::gai_strerror(r);
        return -1;
    }
    int fd = -1;
    std::string last = "no address";
    for (auto* a = found; a != nullptr && fd < 0; a = a->ai_next) {
        fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
        if (fd >= 0 && ::connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
            last = std::strerror(errno);
            ::close(fd);
            fd = -1;
        }
    }
    ::freeaddrinfo(found);
    if (fd < 0) {
        error = "cannot connect to the ground hub at " + host_port + ": " + last;
    }
    return fd;
}

}  // namespace

HubClient::HubClient(HubOptions options) : options_(std::move(options)) {
    std::random_device rd;
    next_id_ = rd();
}

HubClient::~HubClient() {
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

std::string HubClient::open(std::chrono::milliseconds timeout) {
    std::string error;
    fd_ = options_.tcp.empty() ? connect_unix(options_.socket, error) : connect_tcp(options_.tcp, error);
    if (fd_ < 0) {
        return error;
    }
    std::optional<std::array<std::uint8_t, 32>> key;
    if (!options_.key_file.empty()) {
        auto read = groundlink::read_key_file(options_.key_file);
        if (!read.key) {
            return read.error;
        }
        key = read.key;
    }
    const auto deadline = Clock::now() + timeout;
    nlohmann::json greeting;
    pump(deadline, [&](hub::Frame& f) {
        if (f.type == hub::FrameType::Json) {
            greeting = nlohmann::json::parse(f.payload, nullptr, false);
            return true;
        }
        return false;
    });
    if (!greeting.is_object() || !greeting.contains("hub")) {
        return closed_reason_.empty()
                   ? "the ground hub did not greet within " + std::to_string(timeout.count()) + " ms"
                   : closed_reason_;
    }
    nlohmann::json hello{{"want", options_.want_control ? "control" : "monitor"}, {"name", options_.name}};
    if (key) {
        const auto challenge = hub::from_hex(greeting.value("challenge", std::string{}));
        if (!challenge || challenge->size() != hub::kChallengeBytes) {
            return "the ground hub's greeting carries no valid challenge";
        }
        hello["proof"] = hub::to_hex(hub::proof(*key, *challenge));
    }
    if (!send_frame(hub::encode_json({{"hello", hello}}))) {
        return closed_reason_;
    }
    bool welcomed = false;
    pump(deadline, [&](hub::Frame& f) {
        if (f.type != hub::FrameType::Json) {
            return false;
        }
        auto j = nlohmann::json::parse(f.payload, nullptr, false);
        if (j.contains("welcome")) {
            role_ = j["welcome"].value("role", "monitor");
            role_reason_ = j["welcome"].value("reason", "");
            welcomed = true;
            return true;
        }
        take_json(j);
        return false;
    });
    if (!welcomed) {
        return closed_reason_.empty() ? "the ground hub did not answer the hello in time" : closed_reason_;
    }
    return {};
}

bool HubClient::send_frame(const std::vector<std::uint8_t>& frame) {
    std::size_t sent = 0;
    while (sent < frame.size()) {
        const ssize_t n = ::send(fd_, frame.data() + sent, frame.size() - sent, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            closed_reason_ = std::string("the ground hub connection broke: ") + std::strerror(errno);
            return false;
        }
        sent += static_cast<std::size_t>(n);
    }
    return true;
}

bool HubClient::pump(Clock::time_point deadline, const std::function<bool(hub::Frame&)>& on_frame) {
    for (;;) {
        while (auto frame = reader_.next()) {
            if (on_frame(*frame)) {
                return true;
            }
        }
        if (fd_ < 0) {
            return false;
        }
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (left.count() <= 0) {
            return true;
        }
        pollfd p{fd_, POLLIN, 0};
        const int r = ::poll(&p, 1, static_cast<int>(left.count()));
        if (r < 0 && errno == EINTR) {
            return true;  // a signal (Ctrl-C): let the caller look at its stop flag
        }
        if (r <= 0) {
            continue;
        }
        std::uint8_t buf[65536];
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n <= 0) {
            if (closed_reason_.empty()) {
                closed_reason_ = "the ground hub closed the connection";
            }
            ::close(fd_);
            fd_ = -1;
            link_ = {{"link", "down"}};
            continue;  // hand out the frames read before the end
        }
        if (!reader_.push(std::span(buf, static_cast<std::size_t>(n)))) {
            closed_reason_ = "the ground hub sent a broken stream: " + reader_.error();
            ::close(fd_);
            fd_ = -1;
        }
    }
}

void HubClient::take_json(const nlohmann::json& j) {
    if (j.contains("link") && j["link"].is_object()) {
        link_ = j["link"];
    }
    if (j.contains("error") && j["error"].is_string()) {
        closed_reason_ = "the ground hub: " + j["error"].get<std::string>();
    }
}

LocalAnswer HubClient::request(const nlohmann::json& request, std::chrono::milliseconds timeout,
                               const MessageHandler& on_message) {
    LocalAnswer out;
    const std::uint32_t id = next_id_++;
    if (fd_ < 0 ||
        !send_frame(hub::encode(hub::FrameType::Ground, proto::encode(proto::Command{id, request})))) {
        out.error = closed_reason_.empty() ? "not connected to the ground hub" : closed_reason_;
        return out;
    }
    pump(Clock::now() + timeout, [&](hub::Frame& f) {
        if (f.type == hub::FrameType::Json) {
            take_json(nlohmann::json::parse(f.payload, nullptr, false));
            return false;
        }
        auto decoded = proto::decode(f.payload);
        if (decoded.message) {
            if (auto* result = std::get_if<proto::Result>(&*decoded.message);
                result && result->request_id == id) {
                out.answer = result->answer;
                return true;
            }
            if (on_message) {
                on_message(*decoded.message);  // pushed while it waits, as run_for sees it
            }
        }
        return false;
    });
    if (!out.answer) {
        out.error = !closed_reason_.empty() && fd_ < 0
                        ? closed_reason_
                        : fmt::format("no answer from the vehicle within {} ms (through the ground hub; {})",
                                      timeout.count(), link_up() ? "link up" : "no link");
    }
    return out;
}

void HubClient::run_for(std::chrono::milliseconds duration,
                        const std::function<void(const proto::Message&)>& on_message) {
    const auto deadline = Clock::now() + duration;
    pump(deadline, [&](hub::Frame& f) {
        if (f.type == hub::FrameType::Json) {
            take_json(nlohmann::json::parse(f.payload, nullptr, false));
        } else if (auto decoded = proto::decode(f.payload); decoded.message && on_message) {
            on_message(*decoded.message);
        }
        return false;
    });
    if (fd_ < 0 && Clock::now() < deadline) {
        // The hub is gone: the live views show the link down instead of spinning.
        std::this_thread::sleep_until(deadline);
    }
}

void HubClient::send_joystick(double steering, double throttle) {
    if (fd_ >= 0) {
        send_frame(hub::encode(hub::FrameType::Ground, proto::encode(proto::Joystick{steering, throttle})));
    }
}

}  // namespace airseg::client
