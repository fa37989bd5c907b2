#include "hal/pty.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <deque>

#include "hal/current_io.hpp"
#include "hal/io_errors.hpp"
#include "hal/write_queue.hpp"

namespace airseg::hal {
namespace {

std::error_code last_errno() {
    return {errno, std::system_category()};
}

// Points `link` at `target` atomically (a new link renamed over the old one), so a peer never sees the path
// missing during a replug. Refuses to replace anything that is not a symlink.
std::error_code publish_symlink(const std::string& target, const std::string& link, std::string& what) {
    struct stat st {};
    if (::lstat(link.c_str(), &st) == 0 && !S_ISLNK(st.st_mode)) {
        what = "exists and is not a symlink; not replacing it";
        return make_error_code(HalError::PathOccupied);
    }
    const std::string temp = link + ".new";
    ::unlink(temp.c_str());
    if (::symlink(target.c_str(), temp.c_str()) != 0) {
        what = "cannot create symlink " + temp;
        return last_errno();
    }
    if (::rename(temp.c_str(), link.c_str()) != 0) {
        const auto ec = last_errno();
        ::unlink(temp.c_str());
        what = "cannot rename symlink into place";
        return ec;
    }
    return {};
}

// Removes `link` only while it still points at `target`: another process may have claimed the path since.
void remove_symlink_if_ours(const std::string& link, const std::string& target) {
    std::array<char, 512> buf{};
    const ssize_t n = ::readlink(link.c_str(), buf.data(), buf.size() - 1);
    if (n > 0 && std::string(buf.data(), static_cast<std::size_t>(n)) == target) {
        ::unlink(link.c_str());
    }
}

unsigned baud_of(speed_t speed) {
    switch (speed) {
        case B9600:
            return 9600;
        case B19200:
            return 19200;
        case B38400:
            return 38400;
        case B57600:
            return 57600;
        case B115200:
            return 115200;
        case B230400:
            return 230400;
        case B460800:
            return 460800;
        case B500000:
            return 500000;
        case B921600:
            return 921600;
        case B1500000:
            return 1500000;
        default:
            return 0;
    }
}

}  // namespace

std::vector<std::string> PtyConfig::validate(const PtyConfig& config) {
    std::vector<std::string> errors;
    if (config.link_path.empty()) {
        errors.emplace_back("pty: link_path is empty");
    }
    if (config.peer_check_period <= Duration::zero()) {
        errors.push_back("pty[" + config.link_path + "]: peer_check_period must be positive");
    }
    if (config.max_queued_bytes == 0) {
        errors.push_back("pty[" + config.link_path + "]: max_queued_bytes must be greater than 0");
    }
    return errors;
}

class Pty::Impl : public std::enable_shared_from_this<Impl> {
  public:
    Impl(Executor executor, PtyConfig config)
        : config_(std::move(config)),
          prefix_("pty[" + config_.link_path + "]: "),
          stream_(executor),
          timer_(executor) {}

    OpenResult open() {
        OpenResult result;
        if (is_open()) {
            return result;
        }
        if (auto errors = PtyConfig::validate(config_); !errors.empty()) {
            return invalid_config(errors);
        }
        termios raw{};
        ::cfmakeraw(&raw);
        ::cfsetspeed(&raw, B115200);
        int master = -1;
        int slave = -1;
        std::array<char, 128> name{};
        if (::openpty(&master, &slave, name.data(), &raw, nullptr) != 0) {
            result.error = last_errno();
            result.message = prefix_ + "openpty failed: " + result.error.message();
            return result;
        }
        // Holding the slave would hide every peer: the master reports POLLHUP only while no one has it open.
        ::close(slave);
        ::fcntl(master, F_SETFD, FD_CLOEXEC);
        ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);

        std::string what;
        if (auto ec = publish_symlink(name.data(), config_.link_path, what)) {
            ::close(master);
            result.error = ec;
            result.message = prefix_ + what + ": " + ec.message();
            return result;
        }
        boost::system::error_code ec;
        stream_.assign(master, ec);
        if (ec) {
            ::close(master);
            remove_symlink_if_ours(config_.link_path, name.data());
            result.error = {ec.value(), std::system_category()};
            result.message = prefix_ + "cannot register with the event loop: " + ec.message();
            return result;
        }
        slave_path_ = name.data();
        ++epoch_;
        ++generation_;
        peer_ = false;
        spdlog::info("{}plugged, slave {}", prefix_, slave_path_);
        schedule_peer_check();
        return result;
    }

    void unplug() {
        if (!is_open()) {
            return;
        }
        ++epoch_;
        ++generation_;
        timer_.cancel();
        boost::system::error_code ignored;
        stream_.close(ignored);
        remove_symlink_if_ours(config_.link_path, slave_path_);
        spdlog::info("{}unplugged", prefix_);
        slave_path_.clear();
        peer_ = false;
        reset_io_state();
    }

    bool is_open() const { return stream_.is_open(); }
    bool peer_connected() const { return peer_; }
    unsigned peer_baud() {
        termios tio{};
        if (!is_open() || ::tcgetattr(stream_.native_handle(), &tio) != 0) {
            return 0;
        }
        return baud_of(::cfgetospeed(&tio));
    }
    const std::string& link_path() const { return config_.link_path; }
    const std::string& slave_path() const { return slave_path_; }

    void set_on_peer_open(PeerHandler handler) { on_peer_open_ = std::move(handler); }
    void set_on_peer_close(PeerHandler handler) { on_peer_close_ = std::move(handler); }

    void start_reading(BytesHandler on_bytes) {
        on_bytes_ = std::make_shared<const BytesHandler>(std::move(on_bytes));
        if (peer_ && !reading_) {
            do_read();
        }
    }

    void drop_handlers() {
        on_bytes_.reset();
        on_peer_open_ = nullptr;
        on_peer_close_ = nullptr;
    }

    WriteResult write(std::vector<std::uint8_t> bytes) {
        if (!is_open()) {
            return WriteResult::NotOpen;
        }
        if (!peer_) {
            return WriteResult::NoPeer;
        }
        if (const auto r = writes_.push(std::move(bytes), config_.max_queued_bytes);
            r != WriteResult::Queued) {
            return r;
        }
        if (!writing_ && writes_.has_waiting()) {
            do_write();
        }
        return WriteResult::Queued;
    }

    std::size_t queued_bytes() const { return writes_.bytes(); }

  private:
    void schedule_peer_check() {
        timer_.expires_after(config_.peer_check_period);
        timer_.async_wait([self = shared_from_this(), epoch = epoch_](boost::system::error_code ec) {
            self->on_peer_check(epoch, ec);
        });
    }

    void on_peer_check(std::uint64_t epoch, boost::system::error_code ec) {
        if (epoch != epoch_ || ec) {
            return;
        }
        pollfd p{stream_.native_handle(), 0, 0};
        if (::poll(&p, 1, 0) >= 0) {
            set_peer((p.revents & POLLHUP) == 0);
        }
        if (epoch == epoch_) {  // a callback may have unplugged or replugged
            schedule_peer_check();
        }
    }

    void set_peer(bool present) {
        if (present == peer_) {
            return;
        }
        peer_ = present;
        if (present) {
            spdlog::debug("{}peer opened {}", prefix_, slave_path_);
            if (on_bytes_ && !reading_) {
                do_read();
            }
            if (auto cb = on_peer_open_) {
                cb();
            }
        } else {
            spdlog::debug("{}peer closed {}", prefix_, slave_path_);
            // Writes blocked on a pty nobody reads would never finish; end them, as a line drops its bits.
            ++generation_;
            boost::system::error_code ignored;
            stream_.cancel(ignored);
            reset_io_state();
            if (auto cb = on_peer_close_) {
                cb();
            }
        }
    }

    void reset_io_state() {
        reading_ = false;
        writing_ = false;
        writes_.clear();
    }

    void do_read() {
        reading_ = true;
        async_read_current(stream_, boost::asio::buffer(read_buffer_), shared_from_this(), &Impl::generation_,
                           &Impl::on_read);
    }

    // Runs only for a current read (current_io.hpp).
    void on_read(std::uint64_t gen, boost::system::error_code ec, std::size_t n) {
        reading_ = false;
        if (ec) {
            if (is_unplug_error(ec)) {
                set_peer(false);  // EIO on the master: the last peer closed the slave
            } else {
                spdlog::warn("{}read failed ({}); reading resumes when a peer next opens", prefix_,
                             ec.message());
            }
            return;
        }
        if (auto handler = on_bytes_; handler && *handler && n > 0) {
            (*handler)(std::span<const std::uint8_t>(read_buffer_.data(), n));
        }
        if (gen == generation_ && peer_ && on_bytes_ && !reading_) {
            do_read();
        }
    }

    void do_write() {
        writing_ = true;
        auto buffer = std::make_shared<std::vector<std::uint8_t>>(writes_.take_one());
        async_write_current(stream_, boost::asio::buffer(*buffer), buffer, buffer->size(), shared_from_this(),
                            &Impl::generation_, &Impl::on_write);
    }

    // Runs only for a current write (current_io.hpp).
    void on_write(boost::system::error_code ec, std::size_t size) {
        writing_ = false;
        writes_.written(size);
        if (ec) {
            if (is_unplug_error(ec)) {
                set_peer(false);
            } else {
                spdlog::warn("{}write failed ({}); queued bytes dropped", prefix_, ec.message());
                writes_.clear();
            }
            return;
        }
        if (writes_.has_waiting()) {
            do_write();
        }
    }

    PtyConfig config_;
    std::string prefix_;
    boost::asio::posix::stream_descriptor stream_;
    boost::asio::steady_timer timer_;
    std::string slave_path_;
    std::uint64_t epoch_ = 0;       // bumped by open/unplug: stale peer checks stop
    std::uint64_t generation_ = 0;  // bumped whenever pending I/O is abandoned: stale handlers do nothing
    bool peer_ = false;
    bool reading_ = false;
    bool writing_ = false;
    std::shared_ptr<const BytesHandler> on_bytes_;
    PeerHandler on_peer_open_;
    PeerHandler on_peer_close_;
    std::array<std::uint8_t, kReadChunk> read_buffer_{};
    WriteQueue writes_;
};

Pty::Pty(Executor executor, PtyConfig config)
    : impl_(std::make_shared<Impl>(std::move(executor), std::move(config))) {}

Pty::~Pty() {
    impl_->drop_handlers();
    impl_->unplug();
}

OpenResult Pty::open() {
    return impl_->open();
}
void Pty::unplug() {
    impl_->unplug();
}
OpenResult Pty::replug() {
    impl_->unplug();
    return impl_->open();
}
bool Pty::is_open() const {
    return impl_->is_open();
}
unsigned Pty::peer_baud() const {
    return impl_->peer_baud();
}
bool Pty::peer_connected() const {
    return impl_->peer_connected();
}
const std::string& Pty::link_path() const {
    return impl_->link_path();
}
const std::string& Pty::slave_path() const {
    return impl_->slave_path();
}
void Pty::on_peer_open(PeerHandler handler) {
    impl_->set_on_peer_open(std::move(handler));
}
void Pty::on_peer_close(PeerHandler handler) {
    impl_->set_on_peer_close(std::move(handler));
}
void Pty::start_reading(BytesHandler on_bytes) {
    impl_->start_reading(std::move(on_bytes));
}
WriteResult Pty::write(std::vector<std::uint8_t> bytes) {
    return impl_->write(std::move(bytes));
}
std::size_t Pty::queued_bytes() const {
    return impl_->queued_bytes();
}

}  // namespace airseg::hal
