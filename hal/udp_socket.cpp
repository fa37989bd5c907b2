#include "hal/udp_socket.hpp"

#include <spdlog/spdlog.h>

#include <array>

namespace airseg::hal {

namespace {

std::string endpoint_text(const UdpSocket::Endpoint& e) {
    return e.address().to_string() + ":" + std::to_string(e.port());
}

}  // namespace

std::vector<std::string> UdpConfig::validate(const UdpConfig& config) {
    std::vector<std::string> errors;
    boost::system::error_code ec;
    boost::asio::ip::make_address(config.bind_address, ec);
    if (ec) {
        errors.push_back("udp: bind address \"" + config.bind_address + "\" is not an IP address");
    }
    if (!config.remote_address.empty()) {
        boost::asio::ip::make_address(config.remote_address, ec);
        if (ec) {
            errors.push_back("udp: remote address \"" + config.remote_address + "\" is not an IP address");
        }
        if (config.remote_port == 0) {
            errors.push_back("udp: remote address \"" + config.remote_address +
                             "\" given without remote_port");
        }
    } else if (config.remote_port != 0) {
        errors.push_back("udp: remote_port " + std::to_string(config.remote_port) +
                         " given without remote address");
    }
    return errors;
}

class UdpSocket::Impl : public std::enable_shared_from_this<Impl> {
  public:
    explicit Impl(Executor executor) : socket_(executor) {}

    OpenResult open(const UdpConfig& config) {
        close();
        OpenResult result;
        const std::string where =
            "udp[" + config.bind_address + ":" + std::to_string(config.bind_port) + "]: ";
        if (auto errors = UdpConfig::validate(config); !errors.empty()) {
            return invalid_config(errors);
        }
        const Endpoint local(boost::asio::ip::make_address(config.bind_address), config.bind_port);
        boost::system::error_code ec;
        socket_.open(local.protocol(), ec);
        if (!ec) {
            socket_.bind(local, ec);
        }
        if (!ec) {
            socket_.non_blocking(true, ec);  // send_to() tries the kernel first and must never wait
        }
        if (ec) {
            boost::system::error_code ignored;
            socket_.close(ignored);
            result.error = {ec.value(), std::system_category()};
            result.message = where + "cannot bind: " + ec.message();
            return result;
        }
        fixed_remote_.reset();
        last_sender_.reset();
        if (!config.remote_address.empty()) {
            fixed_remote_ =
                Endpoint(boost::asio::ip::make_address(config.remote_address), config.remote_port);
        }
        prefix_ = "udp[" + endpoint_text(socket_.local_endpoint(ec)) + "]: ";
        ++generation_;
        spdlog::info("{}bound{}", prefix_, fixed_remote_ ? ", remote " + endpoint_text(*fixed_remote_) : "");
        return result;
    }

    void close() {
        if (!socket_.is_open()) {
            return;
        }
        boost::system::error_code ignored;
        socket_.close(ignored);
        ++generation_;
        receiving_ = false;
        in_flight_ = 0;
    }

    bool is_open() const { return socket_.is_open(); }

    Endpoint local_endpoint() const {
        boost::system::error_code ec;
        return socket_.local_endpoint(ec);
    }

    std::optional<Endpoint> remote() const { return fixed_remote_ ? fixed_remote_ : last_sender_; }

    void start_receiving(DatagramHandler on_datagram, ErrorHandler on_error) {
        handlers_ = std::make_shared<const Handlers>(Handlers{std::move(on_datagram), std::move(on_error)});
        if (is_open() && !receiving_) {
            receiving_ = true;
            do_receive();
        }
    }

    void drop_handlers() { handlers_.reset(); }

    WriteResult send_to(std::vector<std::uint8_t> datagram, const Endpoint& to) {
        if (!is_open()) {
            return WriteResult::NotOpen;
        }
        if (datagram.size() > kMaxDatagram) {
            return WriteResult::TooLarge;
        }
        if (in_flight_ == 0) {
            // Straight to the kernel while no send waits before it. Completions run on this strand only after
            // the caller's handler returns, so a burst sent from one handler (a whole read of the autopilot's
            // frames, one datagram each) would otherwise meet the in-flight bound after 64 datagrams and lose
            // the rest although the kernel had room for them.
            boost::system::error_code ec;
            socket_.send_to(boost::asio::buffer(datagram), to, 0, ec);
            if (ec != boost::asio::error::would_block && ec != boost::asio::error::try_again) {
                note_send_result(ec);
                return WriteResult::Queued;
            }
        }
        if (in_flight_ >= kMaxSendsInFlight) {
            return WriteResult::QueueFull;
        }
        ++in_flight_;
        auto buffer = std::make_shared<std::vector<std::uint8_t>>(std::move(datagram));
        socket_.async_send_to(boost::asio::buffer(*buffer), to,
                              [self = shared_from_this(), gen = generation_, buffer](
                                  boost::system::error_code ec, std::size_t) { self->on_sent(gen, ec); });
        return WriteResult::Queued;
    }

    WriteResult send(std::vector<std::uint8_t> datagram) {
        const auto to = remote();
        if (!is_open()) {
            return WriteResult::NotOpen;
        }
        if (!to) {
            return WriteResult::NoPeer;
        }
        return send_to(std::move(datagram), *to);
    }

    std::size_t oversize_dropped() const { return oversize_dropped_; }
    std::size_t send_errors() const { return send_errors_; }

  private:
    struct Handlers {
        DatagramHandler on_datagram;
        ErrorHandler on_error;
    };

    void do_receive() {
        socket_.async_receive_from(
            boost::asio::buffer(buffer_), sender_,
            [self = shared_from_this(), gen = generation_](boost::system::error_code ec, std::size_t n) {
                self->on_receive(gen, ec, n);
            });
    }

    void on_receive(std::uint64_t gen, boost::system::error_code ec, std::size_t n) {
        if (gen != generation_ || ec == boost::asio::error::operation_aborted) {
            return;
        }
        if (ec && ec != boost::asio::error::connection_refused) {
            receiving_ = false;
            const std::string what = prefix_ + "receive failed: " + ec.message();
            spdlog::warn("{}", what);
            if (auto handlers = handlers_; handlers && handlers->on_error) {
                handlers->on_error({ec.value(), std::system_category()}, what);
            }
            return;
        }
        if (!ec) {
            // The buffer is one byte larger than the limit, so a datagram that filled it was cut by the
            // kernel.
            if (n > kMaxDatagram) {
                ++oversize_dropped_;
                spdlog::debug("{}dropped a datagram over {} bytes from {}", prefix_, kMaxDatagram,
                              endpoint_text(sender_));
            } else {
                last_sender_ = sender_;
                if (auto handlers = handlers_; handlers && handlers->on_datagram) {
                    handlers->on_datagram(std::span<const std::uint8_t>(buffer_.data(), n), sender_);
                }
            }
        }
        if (gen == generation_ && receiving_) {
            do_receive();
        }
    }

    void on_sent(std::uint64_t gen, boost::system::error_code ec) {
        if (gen != generation_) {
            return;
        }
        --in_flight_;
        note_send_result(ec);
    }

    void note_send_result(boost::system::error_code ec) {
        if (ec && ec != boost::asio::error::operation_aborted) {
            if (send_errors_++ == 0) {
                spdlog::warn("{}send failed: {} (further failures are only counted)", prefix_, ec.message());
            }
        }
    }

    boost::asio::ip::udp::socket socket_;
    std::string prefix_ = "udp[]: ";
    std::uint64_t generation_ = 0;
    std::shared_ptr<const Handlers> handlers_;
    bool receiving_ = false;
    std::array<std::uint8_t, kMaxDatagram + 1> buffer_{};
    Endpoint sender_;
    std::optional<Endpoint> fixed_remote_;
    std::optional<Endpoint> last_sender_;
    std::size_t in_flight_ = 0;
    std::size_t oversize_dropped_ = 0;
    std::size_t send_errors_ = 0;
};

UdpSocket::UdpSocket(Executor executor) : impl_(std::make_shared<Impl>(std::move(executor))) {}
UdpSocket::~UdpSocket() {
    impl_->drop_handlers();
    impl_->close();
}
OpenResult UdpSocket::open(const UdpConfig& config) {
    return impl_->open(config);
}
void UdpSocket::close() {
    impl_->close();
}
bool UdpSocket::is_open() const {
    return impl_->is_open();
}
UdpSocket::Endpoint UdpSocket::local_endpoint() const {
    return impl_->local_endpoint();
}
std::optional<UdpSocket::Endpoint> UdpSocket::remote() const {
    return impl_->remote();
}
void UdpSocket::start_receiving(DatagramHandler on_datagram, ErrorHandler on_error) {
    impl_->start_receiving(std::move(on_datagram), std::move(on_error));
}
WriteResult UdpSocket::send(std::vector<std::uint8_t> datagram) {
    return impl_->send(std::move(datagram));
}
WriteResult UdpSocket::send_to(std::vector<std::uint8_t> datagram, const Endpoint& to) {
    return impl_->send_to(std::move(datagram), to);
}
std::size_t UdpSocket::oversize_dropped() const {
    return impl_->oversize_dropped();
}
std::size_t UdpSocket::send_errors() const {
    return impl_->send_errors();
}

}  // namespace airseg::hal
