// The local command socket's bounds with real Unix sockets: a client that does not read its answers is closed
// at the queue limit, an idle one at the timeout, a full table makes room by closing a client that has asked
// nothing (then the client idle longest), and only clients that all run a request keep a newcomer out (with
// an error line).
#include "services/status/local_command_server.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <future>
#include <thread>

namespace airseg::status {
namespace {

using namespace std::chrono_literals;

bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds timeout = 10s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
        if (condition()) {
            return true;
        }
        std::this_thread::sleep_for(5ms);
    }
    return condition();
}

/// One client end, blocking with a timeout on reads.
class Client {
  public:
    explicit Client(const std::string& path) {
        fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
        connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    }
    ~Client() { ::close(fd_); }
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    bool connected() const { return connected_; }
    /// Sends without blocking; false once the socket takes no more (full, or closed by the server).
    bool send(const std::string& text) {
        std::size_t sent = 0;
        while (sent < text.size()) {
            const ssize_t n =
                ::send(fd_, text.data() + sent, text.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
            if (n <= 0) {
                return false;
            }
            sent += static_cast<std::size_t>(n);
        }
        return true;
    }
    /// The next line, or "" on EOF or timeout.
    std::string line(std::chrono::milliseconds timeout = 5s) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        for (;;) {
            if (const auto nl = buffer_.find('\n'); nl != std::string::npos) {
                std::string out = buffer_.substr(0, nl);
                buffer_.erase(0, nl + 1);
                return out;
            }
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                deadline - std::chrono::steady_clock::now());
            if (left.count() <= 0 || eof_) {
                return {};
            }
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) {
                continue;
            }
            char chunk[65536];
            const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
            if (n <= 0) {
                eof_ = true;
                continue;
            }
            buffer_.append(chunk, static_cast<std::size_t>(n));
        }
    }
    /// True once the server has closed the connection (everything it sent is read and dropped).
    bool closed_by_server(std::chrono::milliseconds timeout = 10s) {
        return wait_until(
            [&] {
                pollfd p{fd_, POLLIN, 0};
                if (::poll(&p, 1, 0) <= 0) {
                    return false;
                }
                char chunk[65536];
                const ssize_t n = ::recv(fd_, chunk, sizeof chunk, MSG_DONTWAIT);
                return n == 0 || (n < 0 && errno != EAGAIN);
            },
            timeout);
    }

  private:
    int fd_ = -1;
    bool connected_ = false;
    bool eof_ = false;
    std::string buffer_;
};

class LocalCommandServerTest : public ::testing::Test {
  protected:
    /// Runs `f` on the server's strand and waits for it.
    void on_strand(const std::function<void()>& f) {
        std::promise<void> done;
        asio::post(strand, [&] {
            f();
            done.set_value();
        });
        done.get_future().get();
    }

    LocalCommandServerTest() {
        dir = std::filesystem::temp_directory_path() /
              ("airseg-lcs-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
        path = (dir / "status.sock").string();
        dispatcher.add("status", strand, Role::Monitor, [](const Json&, CommandDispatcher::Reply reply) {
            reply(CommandResult::ok({{"padding", std::string(4000, 'x')}}));
        });
        dispatcher.add("hold", strand, Role::Monitor, [this](const Json&, CommandDispatcher::Reply reply) {
            held.push_back(std::move(reply));
        });
        dispatcher.add("name", strand, Role::Monitor, [](const Json&, CommandDispatcher::Reply reply) {
            reply(CommandResult::ok({{"name", std::string("plan \xff\xfe")}}));
        });
    }
    ~LocalCommandServerTest() override {
        on_strand([&] {
            server.reset();
            held.clear();
        });
        work = asio::any_io_executor();
        io.stop();
        if (thread.joinable()) {
            thread.join();
        }
        std::error_code ignored;
        std::filesystem::remove_all(dir, ignored);
    }

    void start(Duration idle_timeout = LocalCommandServer::kIdleTimeout) {
        on_strand([&] {
            server = std::make_unique<LocalCommandServer>(strand, dispatcher, idle_timeout);
            EXPECT_EQ(server->open(path, 0600), "");
        });
    }
    LocalSocketStats stats() {
        LocalSocketStats s;
        on_strand([&] { s = server->stats(); });
        return s;
    }
    std::size_t held_count() {
        std::size_t n = 0;
        on_strand([&] { n = held.size(); });
        return n;
    }
    static int& counter() {
        static int n = 0;
        return n;
    }

    asio::io_context io;
    Strand strand = asio::make_strand(io);
    asio::any_io_executor work = asio::prefer(io.get_executor(), asio::execution::outstanding_work.tracked);
    std::thread thread{[this] { io.run(); }};
    CommandDispatcher dispatcher;
    std::unique_ptr<LocalCommandServer> server;
    std::vector<CommandDispatcher::Reply> held;
    std::filesystem::path dir;
    std::string path;
};

TEST_F(LocalCommandServerTest, AClientThatPipelinesAndNeverReadsIsClosedAtTheQueueLimit) {
    start();
    Client greedy(path);
    ASSERT_TRUE(greedy.connected());
    // 20,000 requests of 4 KB answers each: 80 MB if every answer were kept.
    std::size_t sent = 0;
    const std::string request = "{\"cmd\":\"status\"}\n";
    ASSERT_TRUE(wait_until([&] {
        while (sent < 20'000 && greedy.send(request)) {
            ++sent;
        }
        return stats().closed_slow == 1;
    })) << "sent "
        << sent;
    EXPECT_TRUE(greedy.closed_by_server());
    EXPECT_EQ(stats().clients, 0u);
    // A reader is served as before.
    Client reader(path);
    ASSERT_TRUE(reader.send("{\"cmd\":\"status\"}\n"));
    EXPECT_NE(reader.line().find("\"ok\":true"), std::string::npos);
}

TEST_F(LocalCommandServerTest, AnIdleClientIsClosedAfterTheTimeoutAndAReaderIsNot) {
    start(300ms);
    Client idle(path);
    Client busy(path);
    ASSERT_TRUE(idle.connected());
    // A client whose request runs longer than the timeout keeps its connection and gets its answer.
    ASSERT_TRUE(busy.send("{\"cmd\":\"hold\"}\n"));
    ASSERT_TRUE(wait_until([&] { return held_count() == 1; }));
    EXPECT_TRUE(idle.closed_by_server(5s));
    EXPECT_EQ(stats().closed_idle, 1u);
    std::this_thread::sleep_for(400ms);  // past the timeout once more while the request runs
    on_strand([&] { held.front()(CommandResult::ok({{"held", true}})); });
    EXPECT_NE(busy.line().find("\"held\":true"), std::string::npos);
}

TEST_F(LocalCommandServerTest, SixteenIdleClientsDoNotLockANewOneOut) {
    start();
    std::vector<std::unique_ptr<Client>> idle;
    for (std::size_t i = 0; i < LocalCommandServer::kMaxConnections; ++i) {
        idle.push_back(std::make_unique<Client>(path));
    }
    ASSERT_TRUE(wait_until([&] { return stats().clients == LocalCommandServer::kMaxConnections; }));
    Client newcomer(path);
    ASSERT_TRUE(newcomer.send("{\"cmd\":\"status\"}\n"));
    EXPECT_NE(newcomer.line(2s).find("\"ok\":true"), std::string::npos);
    EXPECT_EQ(stats().evicted, 1u);
    EXPECT_EQ(stats().refused, 0u);
    EXPECT_TRUE(idle.front()->closed_by_server()) << "the oldest idle client made room";
}

TEST_F(LocalCommandServerTest, AWatcherBetweenTwoPollsIsNotClosedForSilentNewcomers) {
    start();
    Client watcher(path);
    ASSERT_TRUE(watcher.send("{\"cmd\":\"status\"}\n"));
    ASSERT_NE(watcher.line().find("\"ok\":true"), std::string::npos);
    // Every newcomer connects after the watcher's last answer: by the clock alone the watcher is idle
    // longest.
    std::vector<std::unique_ptr<Client>> silent;
    for (std::size_t i = 0; i < LocalCommandServer::kMaxConnections + 3; ++i) {
        silent.push_back(std::make_unique<Client>(path));
        ASSERT_TRUE(silent.back()->connected());
    }
    ASSERT_TRUE(wait_until([&] { return stats().evicted == 4u; })) << stats().evicted;
    ASSERT_TRUE(watcher.send("{\"cmd\":\"status\"}\n"));
    EXPECT_NE(watcher.line().find("\"ok\":true"), std::string::npos) << "the watcher kept its connection";
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_TRUE(silent[i]->closed_by_server()) << "silent client " << i << " made room, oldest first";
    }
    EXPECT_EQ(stats().clients, LocalCommandServer::kMaxConnections);
}

TEST_F(LocalCommandServerTest, AClientWhoseRequestIsOnItsWayIsNotClosedForSilentNewcomers) {
    start();
    // The first client's request has not all arrived (a slow client, or a daemon behind its clients): to
    // the server it has not asked yet, and it is the oldest connection.
    Client first(path);
    ASSERT_TRUE(first.connected());
    ASSERT_TRUE(first.send("{\"cmd\":"));
    std::vector<std::unique_ptr<Client>> silent;
    for (std::size_t i = 0; i < LocalCommandServer::kMaxConnections + 3; ++i) {
        silent.push_back(std::make_unique<Client>(path));
        ASSERT_TRUE(silent.back()->connected());
    }
    ASSERT_TRUE(wait_until([&] { return stats().evicted == 4u; })) << stats().evicted;
    ASSERT_TRUE(first.send("\"status\"}\n"));
    EXPECT_NE(first.line().find("\"ok\":true"), std::string::npos) << "the first client kept its connection";
    EXPECT_EQ(stats().refused, 0u);
}

TEST_F(LocalCommandServerTest, WhenEveryClientRunsARequestANewcomerIsRefusedWithALine) {
    start();
    std::vector<std::unique_ptr<Client>> busy;
    for (std::size_t i = 0; i < LocalCommandServer::kMaxConnections; ++i) {
        busy.push_back(std::make_unique<Client>(path));
        ASSERT_TRUE(busy.back()->send("{\"cmd\":\"hold\"}\n"));
    }
    ASSERT_TRUE(wait_until([&] { return held_count() == LocalCommandServer::kMaxConnections; }));
    Client newcomer(path);
    const auto answer = newcomer.line();
    EXPECT_NE(answer.find("too many local connections"), std::string::npos) << answer;
    EXPECT_EQ(stats().refused, 1u);
    EXPECT_EQ(stats().evicted, 0u);
}

TEST_F(LocalCommandServerTest, AnAnswerWithInvalidUtf8StillGoesOut) {
    start();
    Client c(path);
    ASSERT_TRUE(c.send("{\"cmd\":\"name\"}\n{\"cmd\":\"status\"}\n"));
    const auto answer = c.line();
    EXPECT_NE(answer.find("\"ok\":true"), std::string::npos) << answer;
    EXPECT_NE(answer.find("plan \xef\xbf\xbd\xef\xbf\xbd"), std::string::npos) << "replaced by U+FFFD";
    EXPECT_NE(c.line().find("\"ok\":true"), std::string::npos) << "and the connection goes on";
}

}  // namespace
}  // namespace airseg::status
