#include "hal/serial_port.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <deque>
#include <iterator>

#include "hal/current_io.hpp"
#include "hal/io_errors.hpp"
#include "hal/serial_termios.hpp"
#include "hal/write_queue.hpp"

namespace airseg::hal {

class SerialPort::Impl : public std::enable_shared_from_this<Impl> {
  public:
    explicit Impl(Executor executor) : executor_(executor), stream_(executor) {}

    OpenResult open(const SerialConfig& config) {
        close();
        config_ = config;
        prefix_ = "serial[" + config.path + "]: ";
        OpenResult result;
        if (auto errors = SerialConfig::validate(config); !errors.empty()) {
            return invalid_config(errors);
        }
        const int fd = ::open(config.path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0) {
            result.error = {errno, std::system_category()};
            result.message = prefix_ + "cannot open: " + result.error.message();
            return result;
        }
        std::string what;
        if (auto ec = termios_setup::apply(fd, config, what)) {
            ::close(fd);
            result.error = ec.value() == ENOTTY ? make_error_code(HalError::NotATerminal) : ec;
            result.message = prefix_ + what + ": " + ec.message();
            return result;
        }
        result.warnings = termios_setup::apply_optional(fd, config);
        // Two openers of one serial line each get part of the bytes and both see garbage; exclusive mode
        // makes a second open (ModemManager probing, a second daemon, a stray terminal) fail with EBUSY
        // instead.
        if (::ioctl(fd, TIOCEXCL) != 0) {
            result.warnings.push_back("cannot take exclusive use of the line (TIOCEXCL): " +
                                      std::error_code(errno, std::system_category()).message());
        }
        for (auto& w : result.warnings) {
            w = prefix_ + w;
            spdlog::warn("{}", w);
        }
        boost::system::error_code ec;
        stream_.assign(fd, ec);
        if (ec) {
            ::close(fd);
            result.error = {ec.value(), std::system_category()};
            result.message = prefix_ + "cannot register with the event loop: " + ec.message();
            return result;
        }
        ++generation_;
        spdlog::info("{}opened at {} baud{}", prefix_, config.baud, config.rtscts ? " with RTS/CTS" : "");
        return result;
    }

    void close() {
        if (!stream_.is_open()) {
            return;
        }
        boost::system::error_code ignored;
        stream_.close(ignored);
        ++generation_;  // handlers of the closed descriptor see a stale generation and do nothing
        reading_ = false;
        writing_ = false;
        writes_.clear();
    }

    bool is_open() const { return stream_.is_open(); }
    const std::string& path() const { return config_.path; }

    void start_reading(BytesHandler on_bytes, ErrorHandler on_error) {
        handlers_ = std::make_shared<const Handlers>(Handlers{std::move(on_bytes), std::move(on_error)});
        if (is_open() && !reading_) {
            reading_ = true;
            do_read();
        }
    }

    void drop_handlers() { handlers_.reset(); }

    WriteResult write(std::vector<std::uint8_t> bytes) {
        if (!is_open()) {
            return WriteResult::NotOpen;
        }
        if (const auto r = writes_.push(std::move(bytes), config_.max_queued_bytes);
            r != WriteResult::Queued) {
            return r;
        }
        if (!writing_ && writes_.has_waiting()) {
            // Deferred by one turn of the event loop, so everything queued in this turn leaves in one write,
            // back to back as a UART sends it: two frames meant together (a mode change and the mission slot
            // right behind it) are not split by whatever else the loop runs, which the board would see as a
            // gap between them.
            writing_ = true;
            boost::asio::post(executor_, [self = shared_from_this(), gen = generation_] {
                if (gen == self->generation_) {
                    self->do_write();
                }
            });
        }
        return WriteResult::Queued;
    }

    std::size_t queued_bytes() const { return writes_.bytes(); }

    std::size_t bytes_waiting() {
        int n = 0;
        if (!is_open() || ::ioctl(stream_.native_handle(), FIONREAD, &n) != 0 || n < 0) {
            return 0;
        }
        return static_cast<std::size_t>(n);
    }

    std::error_code set_line(int bit, bool on) {
        if (!is_open()) {
            return std::make_error_code(std::errc::bad_file_descriptor);
        }
        return termios_setup::set_modem_line(stream_.native_handle(), bit, on);
    }

    Executor get_executor() const { return executor_; }

  private:
    struct Handlers {
        BytesHandler on_bytes;
        ErrorHandler on_error;
    };
    struct Batch {
        std::vector<std::vector<std::uint8_t>> frames;
        std::vector<boost::asio::const_buffer> buffers;
        std::size_t size = 0;
    };

    void do_read() {
        async_read_current(stream_, boost::asio::buffer(read_buffer_), shared_from_this(), &Impl::generation_,
                           &Impl::on_read);
    }

    // Runs only for a current read (current_io.hpp).
    void on_read(std::uint64_t gen, boost::system::error_code ec, std::size_t n) {
        if (ec) {
            fail(ec, HalError::ReadFailed);
            return;
        }
        if (auto handlers = handlers_; handlers && handlers->on_bytes && n > 0) {
            handlers->on_bytes(std::span<const std::uint8_t>(read_buffer_.data(), n));
        }
        if (gen == generation_ && reading_) {  // the handler may have closed or reopened the port
            do_read();
        }
    }

    // Everything queued goes out in one gathered write.
    void do_write() {
        writing_ = true;
        auto batch = std::make_shared<Batch>();
        auto waiting = writes_.take_all();
        batch->frames.assign(std::make_move_iterator(waiting.begin()),
                             std::make_move_iterator(waiting.end()));
        for (const auto& f : batch->frames) {
            batch->buffers.emplace_back(f.data(), f.size());
            batch->size += f.size();
        }
        async_write_current(stream_, batch->buffers, batch, batch->size, shared_from_this(),
                            &Impl::generation_, &Impl::on_write);
    }

    // Runs only for a current write (current_io.hpp).
    void on_write(boost::system::error_code ec, std::size_t size) {
        writing_ = false;
        writes_.written(size);
        if (ec) {
            fail(ec, HalError::WriteFailed);
            return;
        }
        if (writes_.has_waiting()) {
            do_write();
        }
    }

    // Closes the port, then reports once; the caller may reopen from inside on_error.
    void fail(boost::system::error_code ec, HalError otherwise) {
        const bool unplugged = is_unplug_error(ec);
        const HalError code = unplugged ? HalError::Unplugged : otherwise;
        const std::string what =
            prefix_ +
            (unplugged ? "device unplugged ("
                       : (code == HalError::ReadFailed ? "read failed (" : "write failed (")) +
            ec.message() + ")";
        close();
        spdlog::warn("{}", what);
        if (auto handlers = handlers_; handlers && handlers->on_error) {
            handlers->on_error(make_error_code(code), what);
        }
    }

    Executor executor_;
    boost::asio::posix::stream_descriptor stream_;
    SerialConfig config_;
    std::string prefix_ = "serial[]: ";
    std::uint64_t generation_ = 0;
    std::shared_ptr<const Handlers> handlers_;
    bool reading_ = false;
    bool writing_ = false;
    std::array<std::uint8_t, kReadChunk> read_buffer_{};
    WriteQueue writes_;
};

SerialPort::SerialPort(Executor executor) : impl_(std::make_shared<Impl>(std::move(executor))) {}

SerialPort::~SerialPort() {
    // Drop the handlers with the port: pending operations may keep Impl alive a little longer, but they must
    // never call back into an owner that is gone.
    impl_->drop_handlers();
    impl_->close();
}

OpenResult SerialPort::open(const SerialConfig& config) {
    return impl_->open(config);
}
void SerialPort::close() {
    impl_->close();
}
bool SerialPort::is_open() const {
    return impl_->is_open();
}
const std::string& SerialPort::path() const {
    return impl_->path();
}
void SerialPort::start_reading(BytesHandler on_bytes, ErrorHandler on_error) {
    impl_->start_reading(std::move(on_bytes), std::move(on_error));
}
WriteResult SerialPort::write(std::vector<std::uint8_t> bytes) {
    return impl_->write(std::move(bytes));
}
std::size_t SerialPort::queued_bytes() const {
    return impl_->queued_bytes();
}
std::size_t SerialPort::bytes_waiting() const {
    return impl_->bytes_waiting();
}
std::error_code SerialPort::set_dtr(bool on) {
    return impl_->set_line(TIOCM_DTR, on);
}
std::error_code SerialPort::set_rts(bool on) {
    return impl_->set_line(TIOCM_RTS, on);
}
Executor SerialPort::get_executor() const {
    return impl_->get_executor();
}

}  // namespace airseg::hal
