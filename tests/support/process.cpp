#include "tests/support/process.hpp"
#include "tests/support/tree_paths.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace airseg::test {

bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds timeout,
                std::chrono::milliseconds poll) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
        if (std::chrono::steady_clock::now() >= deadline) {
            return false;
        }
        std::this_thread::sleep_for(poll);
    }
    return true;
}

TempDir::TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "airseg-test-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) {
        throw std::runtime_error("mkdtemp failed");
    }
    path_ = tmpl;
}

TempDir::~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

std::string read_file(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

void write_file(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::trunc);
    out << text;
}

std::string binary(const std::string& relative) {
    return binary_dir() + "/" + relative;
}
std::string source_path(const std::string& relative) {
    return source_dir() + "/" + relative;
}

Subprocess::Subprocess(std::vector<std::string> argv, std::map<std::string, std::string> env,
                       const std::string& log_dir) {
    const std::string name = std::filesystem::path(argv.at(0)).filename().string();
    // The output files are claimed here, before the spawn: the child's own open may come later (qemu-user
    // runs posix_spawn's vfork as a fork and does not wait for it), and two children given the same file
    // would interleave their output in it.
    for (int n = 0;; ++n) {
        const std::string stem =
            log_dir + "/" + name + "." + std::to_string(::getpid()) + "." + std::to_string(n);
        const int fd = ::open((stem + ".out").c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd >= 0) {
            ::close(fd);
            out_path_ = stem + ".out";
            err_path_ = stem + ".err";
            break;
        }
        if (errno != EEXIST) {
            throw std::runtime_error("cannot create " + stem + ".out: " + std::strerror(errno));
        }
    }
    std::map<std::string, std::string> merged;
    for (char** e = environ; *e != nullptr; ++e) {
        std::string kv(*e);
        auto eq = kv.find('=');
        if (eq != std::string::npos) {
            merged[kv.substr(0, eq)] = kv.substr(eq + 1);
        }
    }
    for (auto& [k, v] : env) {
        merged[k] = v;
    }
    std::vector<std::string> env_strings;
    for (auto& [k, v] : merged) {
        env_strings.push_back(k + "=" + v);
    }
    std::vector<char*> envp;
    for (auto& s : env_strings) {
        envp.push_back(s.data());
    }
    envp.push_back(nullptr);
    std::vector<char*> args;
    for (auto& a : argv) {
        args.push_back(a.data());
    }
    args.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    const int r = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (r != 0) {
        throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(r));
    }
}

Subprocess::~Subprocess() {
    if (running()) {
        ::kill(pid_, SIGKILL);
        wait_exit(std::chrono::seconds(5));
    }
}

void Subprocess::signal(int signo) const {
    ::kill(pid_, signo);
}

bool Subprocess::running() {
    if (exit_code_) {
        return false;
    }
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return false;
    }
    return r == 0;
}

std::optional<int> Subprocess::wait_exit(std::chrono::milliseconds timeout) {
    if (!wait_until([this] { return !running(); }, timeout, std::chrono::milliseconds(5))) {
        stuck_ =
            "still running " + std::to_string(timeout.count()) + " ms into a wait for its exit:\n" + where();
    }
    return exit_code_;
}

std::string Subprocess::where() {
    if (!running()) {
        return {};
    }
    std::string text;
    const std::filesystem::path tasks = "/proc/" + std::to_string(pid_) + "/task";
    std::error_code ec;
    for (const auto& task : std::filesystem::directory_iterator(tasks, ec)) {
        // stat: "tid (comm) state ..."; the name may hold spaces and parentheses, the state follows the last.
        const std::string stat = read_file((task.path() / "stat").string());
        const auto close = stat.rfind(')');
        const std::string state =
            close != std::string::npos && close + 2 < stat.size() ? stat.substr(close + 2, 1) : "?";
        const auto open = stat.find('(');
        const std::string name = open != std::string::npos && close != std::string::npos
                                     ? stat.substr(open + 1, close - open - 1)
                                     : "";
        text += "  thread " + task.path().filename().string() + " (" + name + "): state " + state +
                ", waits in " + read_file((task.path() / "wchan").string()) + "\n";
        std::istringstream stack(read_file((task.path() / "stack").string()));
        int frames = 0;
        for (std::string line; std::getline(stack, line) && frames < 12; ++frames) {
            text += "    " + line + "\n";
        }
    }
    return text;
}

std::string Subprocess::out() const {
    return read_file(out_path_);
}
std::string Subprocess::err() const {
    return read_file(err_path_);
}

RunResult run(std::vector<std::string> argv, std::map<std::string, std::string> env,
              std::chrono::milliseconds timeout) {
    TempDir logs;
    Subprocess p(std::move(argv), std::move(env), logs.path());
    RunResult result;
    auto code = p.wait_exit(timeout);
    result.exit_code = code.value_or(-1);
    result.out = p.out();
    result.err = p.err();
    return result;
}

NotifyListener::NotifyListener(const std::string& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
    ::unlink(path.c_str());
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        throw std::runtime_error("cannot bind notify socket " + path + ": " + std::strerror(errno));
    }
    reader_ = std::thread([this] { read_until_stopped(); });
}

NotifyListener::~NotifyListener() {
    stop_ = true;
    reader_.join();
    ::close(fd_);
    ::unlink(path_.c_str());
}

// Reads as systemd does, whether or not the test is looking: a socket nobody reads holds 10 datagrams
// (net.unix.max_dgram_qlen), and a slow test would otherwise measure its own pauses.
void NotifyListener::read_until_stopped() {
    char buf[4096];
    while (!stop_) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 20) <= 0) {
            continue;
        }
        for (;;) {
            const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
            if (n <= 0) {
                break;
            }
            std::lock_guard lock(mutex_);
            messages_.push_back(
                {std::chrono::steady_clock::now(), std::string(buf, static_cast<std::size_t>(n))});
        }
    }
}

std::vector<NotifyListener::Message> NotifyListener::messages() const {
    std::lock_guard lock(mutex_);
    return messages_;
}

std::optional<std::chrono::steady_clock::time_point> NotifyListener::wait_for(
    const std::string& needle, std::chrono::milliseconds timeout, std::size_t from_index) {
    std::optional<std::chrono::steady_clock::time_point> found;
    wait_until(
        [&] {
            std::lock_guard lock(mutex_);
            for (std::size_t i = from_index; i < messages_.size(); ++i) {
                if (messages_[i].text.find(needle) != std::string::npos) {
                    found = messages_[i].at;
                    return true;
                }
            }
            return false;
        },
        timeout, std::chrono::milliseconds(2));
    return found;
}

std::size_t NotifyListener::count(const std::string& needle, std::size_t from_index) const {
    std::lock_guard lock(mutex_);
    std::size_t n = 0;
    for (std::size_t i = from_index; i < messages_.size(); ++i) {
        n += messages_[i].text.find(needle) != std::string::npos ? 1 : 0;
    }
    return n;
}

}  // namespace airseg::test
