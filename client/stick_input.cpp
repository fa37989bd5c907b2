#include "client/stick_input.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>

namespace airseg::client {

namespace {

constexpr std::uint8_t kJsEventAxis = 0x02;
constexpr std::uint8_t kJsEventInit = 0x80;

double axis_value(std::int16_t raw) {
    return std::clamp(static_cast<double>(raw) / 32767.0, -1.0, 1.0);
}

void nudge(double& v, double by) {
    v = std::clamp(std::round((v + by) * 100.0) / 100.0, -1.0, 1.0);
}

// Terminal modes belong to hal/ (the only room that includes termios); the keyboard's raw mode goes through
// stty(1) on the inherited standard input instead.
std::optional<std::string> run_stty(const std::string& args) {
    std::string out;
    FILE* p = ::popen(("stty " + args + " 2>/dev/null").c_str(), "r");
    if (p == nullptr) {
        return std::nullopt;
    }
    char buf[512];
    while (std::fgets(buf, sizeof buf, p) != nullptr) {
        out += buf;
    }
    if (::pclose(p) != 0) {
        return std::nullopt;
    }
    return out;
}

}  // namespace

void JsEventDecoder::feed(std::span<const std::uint8_t> bytes) {
    for (auto b : bytes) {
        partial_[have_++] = b;
        if (have_ < partial_.size()) {
            continue;
        }
        have_ = 0;
        // struct js_event is in the host's byte order (the kernel writes it natively).
        const std::uint16_t lo = partial_[4], hi = partial_[5];
        const auto raw = static_cast<std::uint16_t>(
            std::endian::native == std::endian::little ? lo | (hi << 8) : hi | (lo << 8));
        const auto value = static_cast<std::int16_t>(raw);
        const std::uint8_t type = partial_[6] & static_cast<std::uint8_t>(~kJsEventInit);
        const std::uint8_t number = partial_[7];
        if (type != kJsEventAxis) {
            continue;
        }
        if (number == 0) {
            stick_.steering = axis_value(value);
        } else if (number == 1) {
            stick_.throttle = -axis_value(value);
        }
    }
}

void KeyboardDecoder::feed(std::span<const std::uint8_t> bytes) {
    for (auto b : bytes) {
        const char c = static_cast<char>(b);
        if (escape_ == 1) {
            escape_ = c == '[' ? 2 : 0;
            continue;
        }
        if (escape_ == 2) {
            escape_ = 0;
            switch (c) {
                case 'A':
                    nudge(stick_.throttle, step_);
                    break;
                case 'B':
                    nudge(stick_.throttle, -step_);
                    break;
                case 'C':
                    nudge(stick_.steering, step_);
                    break;
                case 'D':
                    nudge(stick_.steering, -step_);
                    break;
                default:
                    break;
            }
            continue;
        }
        switch (c) {
            case '\x1b':
                escape_ = 1;
                break;
            case 'w':
                nudge(stick_.throttle, step_);
                break;
            case 's':
                nudge(stick_.throttle, -step_);
                break;
            case 'd':
                nudge(stick_.steering, step_);
                break;
            case 'a':
                nudge(stick_.steering, -step_);
                break;
            case ' ':
                stick_.steering = stick_.throttle = 0;
                break;
            case 'q':
            case '\x03':  // Ctrl-C in raw mode
                stick_.quit = true;
                break;
            default:
                break;
        }
    }
}

std::unique_ptr<StickSource> StickSource::open(const std::string& device, std::string& error) {
    std::unique_ptr<StickSource> s(new StickSource());
    if (device.empty()) {
        s->keyboard_ = true;
        s->fd_ = STDIN_FILENO;
        if (::isatty(STDIN_FILENO) == 1) {
            auto saved = run_stty("-g").value_or("");
            while (!saved.empty() && (saved.back() == '\n' || saved.back() == '\r')) {
                saved.pop_back();
            }
            // `stty -g` prints hex fields separated by colons; anything else is not passed back to a shell.
            const bool plain =
                !saved.empty() && saved.find_first_not_of("0123456789abcdefABCDEF:") == std::string::npos;
            if (plain && run_stty("raw -echo opost")) {
                s->saved_terminal_ = saved;
                s->restore_terminal_ = true;
            }
        }
    } else {
        s->fd_ = ::open(device.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
        if (s->fd_ < 0) {
            error = "cannot open joystick " + device + ": " + std::strerror(errno);
            return nullptr;
        }
        s->owns_fd_ = true;
    }
    const int flags = ::fcntl(s->fd_, F_GETFL);
    if (flags >= 0) {
        ::fcntl(s->fd_, F_SETFL, flags | O_NONBLOCK);
    }
    return s;
}

StickSource::~StickSource() {
    if (restore_terminal_) {
        run_stty(saved_terminal_);
    }
    if (keyboard_) {
        const int flags = ::fcntl(fd_, F_GETFL);
        if (flags >= 0) {
            ::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
        }
    }
    if (owns_fd_) {
        ::close(fd_);
    }
}

bool StickSource::poll() {
    std::array<std::uint8_t, 256> buf{};
    for (;;) {
        const auto n = ::read(fd_, buf.data(), buf.size());
        if (n > 0) {
            const std::span<const std::uint8_t> got(buf.data(), static_cast<std::size_t>(n));
            if (keyboard_) {
                keys_.feed(got);
            } else {
                js_.feed(got);
            }
            continue;
        }
        if (n == 0) {
            return false;  // end of file: the device (or the pipe feeding it) is gone
        }
        return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
    }
}

Stick StickSource::stick() const {
    return keyboard_ ? keys_.stick() : js_.stick();
}

}  // namespace airseg::client
