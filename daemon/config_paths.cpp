#include "daemon/config_paths.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <filesystem>
#include <system_error>

#include "base/utf8.hpp"

namespace airseg::daemon {

namespace {

namespace fs = std::filesystem;

/// A path in a message: long enough for /dev/serial/by-id/ names, cut before it drowns the message.
std::string shown(const std::string& path) {
    return excerpt(path, 256);
}

/// The device a path reaches, through symlinks such as /dev/serial/by-id/..., when it exists.
std::string device_of(const std::string& path) {
    std::error_code ec;
    const auto canonical = fs::weakly_canonical(path, ec);
    return ec ? path : canonical.string();
}

void check_port(const std::string& key, const std::string& path, std::vector<KeyProblem>& out) {
    if (path.empty()) {
        return;
    }
    if (!fs::path(path).is_absolute()) {
        out.push_back({key, fmt::format("'{}' is a relative path; give the device's absolute path, e.g. "
                                        "/dev/ttyUSB0 (the service runs in /)",
                                        shown(path))});
        return;
    }
    // A missing device is normal (a USB adapter unplugged): the service waits for it. One that exists
    // must be a character device; a pty slave counts, as the simulators use them.
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && !S_ISCHR(st.st_mode)) {
        out.push_back({key, fmt::format("'{}' is not a serial device ({})", shown(path),
                                        S_ISDIR(st.st_mode) ? "a directory" : "not a character device")});
    }
}

bool is_within(const std::string& path, const std::string& dir) {
    const auto p = fs::path(path).lexically_normal().string();
    return p == dir || p.starts_with(dir + "/");
}

}  // namespace

std::vector<KeyProblem> port_problems(const Config& c) {
    std::vector<KeyProblem> out;
    check_port("autopilot.port", c.autopilot.port, out);
    if (c.groundlink.mode == "udp") {
        return out;  // the radio ports are not opened
    }
    for (const auto& port : c.groundlink.ports) {
        check_port("groundlink.ports", port, out);
    }
    if (!out.empty() || c.autopilot.port.empty()) {
        return out;
    }
    const auto autopilot = device_of(c.autopilot.port);
    for (const auto& port : c.groundlink.ports) {
        if (device_of(port) == autopilot) {
            out.push_back({"groundlink.ports",
                           fmt::format("'{}' is the autopilot's device ({}): the autopilot and a radio "
                                       "need a port each",
                                       shown(port), shown(autopilot))});
        }
    }
    return out;
}

const std::vector<std::string>& unit_writable_dirs() {
    static const std::vector<std::string> dirs{"/var/lib/airseg", "/var/log/airseg", "/run/airseg"};
    return dirs;
}

std::vector<KeyProblem> unwritable_path_warnings(const Config& c) {
    std::vector<KeyProblem> out;
    auto check = [&out](const std::string& key, const std::string& path) {
        for (const auto& dir : unit_writable_dirs()) {
            if (is_within(path, dir)) {
                return;
            }
        }
        out.push_back({key, fmt::format("'{}' is outside the directories airsegd.service can write ({}); "
                                        "under systemd writing it fails unless a drop-in adds "
                                        "ReadWritePaths= (systemctl edit airsegd)",
                                        shown(path), fmt::join(unit_writable_dirs(), ", "))});
    };
    check("state_dir", c.state_dir);
    check("status.socket", c.status.socket);
    if (c.autopilot.tlog_enabled) {
        check("autopilot.tlog.path", c.autopilot.tlog_path);
    }
    return out;
}

}  // namespace airseg::daemon
