#include "tools/common/control_socket.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <array>

namespace airseg::toolcommon {

namespace local = boost::asio::local;

struct ControlSocket::State : std::enable_shared_from_this<ControlSocket::State> {
    State(hal::Executor executor, Handler h) : socket(executor), handler(std::move(h)) {}

    void do_receive() {
        socket.async_receive_from(boost::asio::buffer(buffer), sender,
                                  [self = shared_from_this()](const boost::system::error_code& ec,
                                                              std::size_t n) { self->on_receive(ec, n); });
    }

    void on_receive(const boost::system::error_code& ec, std::size_t n) {
        if (ec == boost::asio::error::operation_aborted || !socket.is_open()) {
            return;
        }
        if (!ec) {
            std::string command(buffer.data(), n);
            while (!command.empty() && (command.back() == '\n' || command.back() == '\r')) {
                command.pop_back();
            }
            std::string reply = handler(command);
            reply.push_back('\n');
            if (!sender.path().empty()) {
                boost::system::error_code ignored;  // a sender that went away gets no reply
                socket.send_to(boost::asio::buffer(reply), sender, 0, ignored);
            }
        }
        do_receive();
    }

    local::datagram_protocol::socket socket;
    local::datagram_protocol::endpoint sender;
    std::array<char, kMaxDatagram> buffer{};
    Handler handler;
};

ControlSocket::ControlSocket(hal::Executor executor, std::string path, Handler handler)
    : state_(std::make_shared<State>(executor, std::move(handler))), path_(std::move(path)) {}

ControlSocket::~ControlSocket() {
    if (state_->socket.is_open()) {
        boost::system::error_code ignored;
        state_->socket.close(ignored);
        ::unlink(path_.c_str());
    }
}

std::error_code ControlSocket::open(std::string& message) {
    struct stat st {};
    if (::lstat(path_.c_str(), &st) == 0) {
        if (!S_ISSOCK(st.st_mode)) {
            message = "control socket " + path_ + ": exists and is not a socket; not replacing it";
            return std::make_error_code(std::errc::file_exists);
        }
        ::unlink(path_.c_str());
    }
    boost::system::error_code ec;
    state_->socket.open(local::datagram_protocol(), ec);
    if (!ec) {
        state_->socket.bind(local::datagram_protocol::endpoint(path_), ec);
    }
    if (ec) {
        message = "control socket " + path_ + ": " + ec.message();
        return {ec.value(), std::system_category()};
    }
    state_->do_receive();
    return {};
}

}  // namespace airseg::toolcommon
