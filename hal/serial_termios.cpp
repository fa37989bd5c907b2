#include "hal/serial_termios.hpp"

#include <linux/serial.h>
#include <sys/ioctl.h>
#include <termios.h>

#include <cerrno>

namespace airseg::hal::termios_setup {
namespace {

speed_t speed_constant(unsigned baud) {
    switch (baud) {
        case 9600:
            return B9600;
        case 19200:
            return B19200;
        case 38400:
            return B38400;
        case 57600:
            return B57600;
        case 115200:
            return B115200;
        case 230400:
            return B230400;
        case 460800:
            return B460800;
        case 500000:
            return B500000;
        case 921600:
            return B921600;
        default:
            return B0;
    }
}

std::error_code last_errno() {
    return {errno, std::system_category()};
}

}  // namespace

std::error_code apply(int fd, const SerialConfig& config, std::string& what) {
    const speed_t speed = speed_constant(config.baud);
    if (speed == B0) {
        what = "baud " + std::to_string(config.baud) + " is not supported";
        return std::make_error_code(std::errc::invalid_argument);
    }
    termios tio{};
    if (::tcgetattr(fd, &tio) != 0) {
        what = "not a terminal (tcgetattr failed)";
        return last_errno();
    }
    ::cfmakeraw(&tio);
    tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS | HUPCL);
    tio.c_cflag |= CS8 | CLOCAL | CREAD;
    if (config.rtscts) {
        tio.c_cflag |= CRTSCTS;
    }
    if (config.hupcl) {
        tio.c_cflag |= HUPCL;
    }
    tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    // The descriptor is non-blocking, so VMIN/VTIME only matter to anyone who later reads it blocking.
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0) {
        what = "cannot set baud " + std::to_string(config.baud);
        return last_errno();
    }
    if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
        what = "tcsetattr failed";
        return last_errno();
    }
    // tcsetattr succeeds when any one setting took; read back to catch a driver that ignored the rate.
    termios applied{};
    if (::tcgetattr(fd, &applied) == 0 && ::cfgetospeed(&applied) != speed) {
        what = "driver did not accept baud " + std::to_string(config.baud);
        return std::make_error_code(std::errc::invalid_argument);
    }
    // Bytes left over from a previous user of the port would be misframed noise.
    ::tcflush(fd, TCIOFLUSH);
    return {};
}

std::error_code set_modem_line(int fd, int line_bit, bool on) {
    int bits = line_bit;
    if (::ioctl(fd, on ? TIOCMBIS : TIOCMBIC, &bits) != 0) {
        return last_errno();
    }
    return {};
}

std::error_code set_low_latency(int fd) {
    serial_struct serial{};
    if (::ioctl(fd, TIOCGSERIAL, &serial) != 0) {
        return last_errno();
    }
    serial.flags |= ASYNC_LOW_LATENCY;
    if (::ioctl(fd, TIOCSSERIAL, &serial) != 0) {
        return last_errno();
    }
    return {};
}

std::vector<std::string> apply_optional(int fd, const SerialConfig& config) {
    std::vector<std::string> warnings;
    auto drive = [&](const std::optional<bool>& wanted, int bit, const char* name) {
        if (!wanted.has_value()) {
            return;
        }
        if (auto ec = set_modem_line(fd, bit, *wanted)) {
            warnings.push_back(std::string("cannot ") + (*wanted ? "raise " : "drop ") + name + ": " +
                               ec.message());
        }
    };
    drive(config.dtr_on_open, TIOCM_DTR, "DTR");
    if (!config.rtscts) {
        drive(config.rts_on_open, TIOCM_RTS, "RTS");
    }
    if (config.low_latency) {
        if (auto ec = set_low_latency(fd)) {
            warnings.push_back("low-latency mode refused: " + ec.message());
        }
    }
    return warnings;
}

}  // namespace airseg::hal::termios_setup
