#include "services/status/local_command_server.hpp"

#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <deque>
#include <filesystem>

namespace airseg::status {

namespace fs = std::filesystem;
using Protocol = asio::local::stream_protocol;

class LocalCommandServer::Session : public std::enable_shared_from_this<Session> {
  public:
    Session(LocalCommandServer& server, Protocol::socket socket)
        : server_(server),
          server_alive_(server.alive_),
          socket_(std::move(socket)),
          input_(kMaxRequestBytes) {}

    void start() { do_read(); }
    void close() {
        boost::system::error_code ignored;
        socket_.close(ignored);
    }

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
        if (ec == asio::error::not_found) {
            // The buffer is full without a newline: answer once, then drop the connection.
            send_line(CommandResult::fail(CommandStatus::BadRequest, "request longer than 1 MiB").to_json(),
                      true);
            return;
        }
        if (ec || !*server_alive_) {
            finish();
            return;
        }
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
            send_line(CommandResult::fail(CommandStatus::BadRequest, "request is not valid JSON").to_json(),
                      false);
            do_read();
            return;
        }
        // Answers are written in request order; the next request is read only after this one's answer.
        server_.dispatcher_.dispatch(
            request, Role::Control, [self = shared_from_this()](CommandResult result) {
                asio::dispatch(self->socket_.get_executor(), [self, result = std::move(result)] {
                    if (!*self->server_alive_) {
                        return;
                    }
                    self->send_line(result.to_json(), false);
                    self->do_read();
                });
            });
    }

    void send_line(const Json& value, bool close_after) {
        // Texts from the autopilot (STATUSTEXT, parameter names) may be any bytes: shown, never thrown on.
        outbox_.push_back(value.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n");
        close_after_ = close_after_ || close_after;
        if (outbox_.size() == 1) {
            do_write();
        }
    }

    void do_write() {
        asio::async_write(
            socket_, asio::buffer(outbox_.front()),
            asio::bind_executor(server_.strand_,
                                [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
                                    self->outbox_.pop_front();
                                    if (ec) {
                                        self->finish();
                                    } else if (!self->outbox_.empty()) {
                                        self->do_write();
                                    } else if (self->close_after_) {
                                        self->finish();
                                    }
                                }));
    }

    void finish() {
        close();
        if (*server_alive_) {
            server_.sessions_.erase(shared_from_this());
        }
    }

    LocalCommandServer& server_;
    std::shared_ptr<bool> server_alive_;  // handlers may outlive the server during shutdown
    Protocol::socket socket_;
    asio::streambuf input_;
    std::deque<std::string> outbox_;
    bool close_after_ = false;
};

LocalCommandServer::LocalCommandServer(Strand strand, const CommandDispatcher& dispatcher)
    : strand_(std::move(strand)), dispatcher_(dispatcher), acceptor_(strand_) {}

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

void LocalCommandServer::do_accept() {
    acceptor_.async_accept(
        asio::bind_executor(strand_, [this](boost::system::error_code ec, Protocol::socket socket) {
            if (ec == asio::error::operation_aborted) {
                return;
            }
            if (!ec) {
                if (sessions_.size() >= kMaxConnections) {
                    spdlog::warn("status: refusing a local connection: {} already open", kMaxConnections);
                } else {
                    auto session = std::make_shared<Session>(*this, std::move(socket));
                    sessions_.insert(session);
                    session->start();
                }
            }
            if (acceptor_.is_open()) {
                do_accept();
            }
        }));
}

}  // namespace airseg::status
