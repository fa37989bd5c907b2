#include "tests/support/control_client.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace airseg::test {
namespace {

sockaddr_un address(const std::string& path) {
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
    return a;
}

}  // namespace

ControlClient::ControlClient(std::string own, std::string server)
    : own_(std::move(own)), server_(std::move(server)) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un a = address(own_);
    ::unlink(own_.c_str());
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        ADD_FAILURE() << "cannot bind " << own_ << ": " << std::strerror(errno);
    }
}

ControlClient::~ControlClient() {
    ::close(fd_);
    ::unlink(own_.c_str());
}

std::optional<std::string> ControlClient::ask(const std::string& text, std::chrono::milliseconds timeout) {
    sockaddr_un a = address(server_);
    if (::sendto(fd_, text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a) < 0) {
        return std::nullopt;
    }
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) {
        return std::nullopt;
    }
    std::string buf(256 * 1024, '\0');  // the reached log pages are the largest replies
    const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
    buf.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return buf;
}

nlohmann::json ControlClient::json(const std::string& text) {
    const auto reply = ask(text);
    if (!reply) {
        ADD_FAILURE() << "simulator: no reply to '" << text << "'";
        return nlohmann::json::object();
    }
    auto j = nlohmann::json::parse(*reply, nullptr, false);
    if (j.is_discarded()) {
        ADD_FAILURE() << "simulator: no JSON reply to '" << text << "': " << *reply;
        return nlohmann::json::object();
    }
    return j;
}

nlohmann::json ControlClient::try_json(const std::string& text) {
    auto j = nlohmann::json::parse(ask(text).value_or(""), nullptr, false);
    return j.is_discarded() ? nlohmann::json::object() : j;
}

}  // namespace airseg::test
