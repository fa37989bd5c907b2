#include "services/status/local_command_server.hpp"

#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <deque>
#include <filesystem>

namespace airseg::status {

namespace fs = std::filesystem;
using Protocol = asio::local::stream_protocol;

namespace {
// Text from outside (a plan's name, an autopilot's parameter) may be invalid UTF-8: an answer replaces such
// bytes rather than throwing out of the dump, which would leave the client without an answer.
std::string answer_line(const Json& value) {
    return value.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}
}  // namespace

class LocalCommandServer::Session : public std::enable_shared_from_this<Session> {
  public:
    Session(LocalCommandServer& server, Protocol::socket socket)
        : server_(server),
          server_alive_(server.alive_),
          socket_(std::move(socket)),
          input_(kMaxRequestBytes),
          idle_timer_(server.strand_),
          last_active_(SteadyClock::now()) {}

    void start() {
        arm_idle(last_active_ + server_.idle_timeout_);
        do_read();
    }
    /// Closes the socket; the session leaves the table once its handlers have run.
    void close() {
        closed_ = true;
        boost::system::error_code ignored;
        socket_.close(ignored);
        idle_timer_.cancel();
    }
    /// Closes it and takes it out of the table now.
    void finish() {
        close();
        if (*server_alive_) {
            server_.sessions_.erase(shared_from_this());
        }
    }
    /// Waiting for a request of its own to be answered: not idle, whatever the clock says.
    bool busy() const { return in_flight_; }
    /// Has sent no request since it connected: it holds a place without using it.
    bool silent() const { return !asked_; }
    /// Bytes of a request sent and not yet read: a daemon slower than its client has not seen it ask.
    bool has_unread_request() const {
        boost::system::error_code ec;
        return input_.size() > 0 || socket_.available(ec) > 0;
    }
    TimePoint last_active() const { return last_active_; }

  private:
    void do_read() {
        asio::async_read_until(
            socket_, input_, '\n',
            asio::bind_executor(server_.strand_,
                                [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
                                    self->on_read(ec, n);
                                }));
    }

    void on_read(boost::system::error_code ec, std::size_t n) {
        if (closed_ || !*server_alive_) {
            return;
        }
        if (ec == asio::error::not_found) {
            // The buffer is full without a newline: answer once, then drop the connection.
            send_line(CommandResult::fail(CommandStatus::BadRequest, "request longer than 1 MiB").to_json(),
                      true);
            return;
        }
        if (ec) {
            finish();
            return;
        }
        last_active_ = SteadyClock::now();
        asked_ = true;
        std::string line(asio::buffers_begin(input_.data()), asio::buffers_begin(input_.data()) + n);
        input_.consume(n);
        while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) {
            line.pop_back();
        }
        if (line.empty()) {
            do_read();
            return;
        }
        Json request = Json::parse(line, nullptr, false);
        if (request.is_discarded()) {
            if (send_line(
                    CommandResult::fail(CommandStatus::BadRequest, "request is not valid JSON").to_json(),
                    false)) {
                do_read();
            }
            return;
        }
        // Answers are written in request order; the next request is read only after this one's answer.
        in_flight_ = true;
        server_.dispatcher_.dispatch(
            request, Role::Control, [self = shared_from_this()](CommandResult result) {
                asio::dispatch(self->socket_.get_executor(), [self, result = std::move(result)] {
                    if (!*self->server_alive_ || self->closed_) {
                        return;
                    }
                    self->in_flight_ = false;
                    self->last_active_ = SteadyClock::now();
                    if (self->send_line(result.to_json(), false)) {
                        self->do_read();
                    }
                });
            });
    }

    /// Queues one answer; false when the client was closed instead because it does not read its answers.
    bool send_line(const Json& value, bool close_after) {
        std::string line = answer_line(value);
        // One answer is always taken, however long (the socket's own buffer then holds what it can); beyond
        // that, answers pile up only for a client that does not read them.
        if (!outbox_.empty() && queued_bytes_ + line.size() > kMaxQueuedBytes) {
            ++server_.stats_.closed_slow;
            server_.log_.log(
                "status: closing a local client that does not read its answers", SteadyClock::now(),
                spdlog::level::warn,
                "status: closing a local client that does not read its answers ({} bytes waiting, "
                "limit {})",
                queued_bytes_ + line.size(), kMaxQueuedBytes);
            finish();
            return false;
        }
        queued_bytes_ += line.size();
        outbox_.push_back(std::move(line));
        close_after_ = close_after_ || close_after;
        if (outbox_.size() == 1) {
            do_write();
        }
        return true;
    }

    void do_write() {
        asio::async_write(
            socket_, asio::buffer(outbox_.front()),
            asio::bind_executor(server_.strand_,
                                [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                                    if (self->closed_ || !*self->server_alive_) {
                                        return;
                                    }
                                    self->queued_bytes_ -= self->outbox_.front().size();
                                    self->outbox_.pop_front();
                                    self->last_active_ = SteadyClock::now();
                                    if (ec) {
                                        self->finish();
                                    } else if (!self->outbox_.empty()) {
                                        self->do_write();
                                    } else if (self->close_after_) {
                                        self->finish();
                                    }
                                }));
    }

    // One timer per client, re-armed only when it fires: activity just moves last_active_.
    void arm_idle(TimePoint at) {
        idle_timer_.expires_at(at);
        idle_timer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
            if (ec || self->closed_ || !*self->server_alive_) {
                return;
            }
            const TimePoint now = SteadyClock::now();
            const TimePoint due = self->last_active_ + self->server_.idle_timeout_;
            if (self->in_flight_ || now < due) {
                self->arm_idle(self->in_flight_ ? now + self->server_.idle_timeout_ : due);
                return;
            }
            // Nothing came and nothing was taken: a client that holds its answers unread is a slow one.
            const bool unread = !self->outbox_.empty();
            ++(unread ? self->server_.stats_.closed_slow : self->server_.stats_.closed_idle);
            self->server_.log_.log(
                "status: closing an idle local client", now, spdlog::level::info,
                "status: closing a local client {} for {} s",
                unread ? "that does not read its answers" : "idle",
                std::chrono::duration_cast<std::chrono::seconds>(self->server_.idle_timeout_).count());
            self->finish();
        });
    }

    LocalCommandServer& server_;
    std::shared_ptr<bool> server_alive_;  // handlers may outlive the server during shutdown
    Protocol::socket socket_;
    asio::streambuf input_;
    std::deque<std::string> outbox_;
    std::size_t queued_bytes_ = 0;
    asio::steady_timer idle_timer_;
    TimePoint last_active_;
    bool in_flight_ = false;
    bool asked_ = false;
    bool close_after_ = false;
    bool closed_ = false;
};

LocalCommandServer::LocalCommandServer(Strand strand, const CommandDispatcher& dispatcher,
                                       Duration idle_timeout)
    : strand_(std::move(strand)), dispatcher_(dispatcher), idle_timeout_(idle_timeout), acceptor_(strand_) {}

LocalCommandServer::~LocalCommandServer() {
    close();
    *alive_ = false;
}

std::string LocalCommandServer::open(const std::string& path, unsigned mode) {
    std::error_code fec;
    const fs::path p(path);
    if (p.has_parent_path()) {
        fs::create_directories(p.parent_path(), fec);
        if (fec) {
            return "cannot create " + p.parent_path().string() + ": " + fec.message();
        }
    }
    // A socket file left by a previous run (kill -9) would make bind fail; anything else is not ours to
    // remove.
    if (fs::is_socket(fs::symlink_status(p, fec))) {
        fs::remove(p, fec);
    } else if (fs::exists(fs::symlink_status(p, fec))) {
        return path + " exists and is not a socket";
    }
    boost::system::error_code ec;
    acceptor_.open(Protocol(), ec);
    if (!ec) {
        acceptor_.bind(Protocol::endpoint(path), ec);
    }
    if (!ec) {
        acceptor_.listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        boost::system::error_code ignored;
        acceptor_.close(ignored);
        return "cannot listen on " + path + ": " + ec.message();
    }
    if (::chmod(path.c_str(), static_cast<mode_t>(mode)) != 0) {
        spdlog::warn("status: cannot set mode {:04o} on {}", mode, path);
    }
    path_ = path;
    do_accept();
    return {};
}

void LocalCommandServer::close() {
    if (acceptor_.is_open()) {
        boost::system::error_code ignored;
        acceptor_.close(ignored);
        std::error_code fec;
        fs::remove(path_, fec);
    }
    for (const auto& s : sessions_) {
        s->close();
    }
    sessions_.clear();
}

LocalSocketStats LocalCommandServer::stats() const {
    LocalSocketStats s = stats_;
    s.clients = sessions_.size();
    return s;
}

void LocalCommandServer::do_accept() {
    acceptor_.async_accept(
        asio::bind_executor(strand_, [this](boost::system::error_code ec, Protocol::socket socket) {
            if (ec == asio::error::operation_aborted) {
                return;
            }
            if (!ec) {
                admit(std::move(socket));
            }
            if (acceptor_.is_open()) {
                do_accept();
            }
        }));
}

// A full table must not lock the board out: a client that has never asked anything makes room first (the
// one connected longest), then the client idle longest. A watcher between two polls is idle longer than a
// burst of silent newcomers, and must not be the one closed for them; nor may a client whose request is
// waiting to be read (a daemon behind its clients has not seen it yet). Only clients that all wait for an
// answer of their own keep a newcomer out.
void LocalCommandServer::admit(Protocol::socket socket) {
    const TimePoint now = SteadyClock::now();
    if (sessions_.size() >= kMaxConnections) {
        std::shared_ptr<Session> oldest;
        const auto closes_before = [](const Session& a, const Session& b) {
            if (a.silent() != b.silent()) {
                return a.silent();
            }
            return a.last_active() < b.last_active();
        };
        for (const auto& s : sessions_) {
            if (!s->busy() && !s->has_unread_request() && (!oldest || closes_before(*s, *oldest))) {
                oldest = s;
            }
        }
        if (!oldest) {
            ++stats_.refused;
            log_.log("status: refusing a local connection", now, spdlog::level::warn,
                     "status: refusing a local connection: {} open, each running a request", kMaxConnections);
            // Best effort and never blocking: the newcomer's first read then says why.
            const std::string why = answer_line(
                CommandResult::fail(CommandStatus::Failed, "too many local connections (" +
                                                               std::to_string(kMaxConnections) +
                                                               ", each running a request); try again")
                    .to_json());
            boost::system::error_code ignored;
            socket.non_blocking(true, ignored);
            socket.write_some(asio::buffer(why), ignored);
            return;
        }
        ++stats_.evicted;
        log_.log("status: closing the local client idle longest", now, spdlog::level::info,
                 "status: {} local connections open: closing {} idle for {} ms to make room", kMaxConnections,
                 oldest->silent() ? "one that has asked nothing," : "the one",
                 std::chrono::duration_cast<std::chrono::milliseconds>(now - oldest->last_active()).count());
        oldest->finish();
    }
    ++stats_.accepted;
    auto session = std::make_shared<Session>(*this, std::move(socket));
    sessions_.insert(session);
    session->start();
}

}  // namespace airseg::status
