#pragma once
// The rules about paths in the configuration that need the file system: ports that cannot be serial devices,
// and paths the systemd unit does not let the daemon write.
#include <string>
#include <vector>

#include "daemon/config.hpp"

namespace airseg::daemon {

struct KeyProblem {
    std::string key;  // the dotted key to blame
    std::string message;
};

/// Errors: a relative port path (the unit's working directory is /), a path that exists but is not a
/// character device (a typo that names a file), and the autopilot and a radio on the same device.
std::vector<KeyProblem> port_problems(const Config& config);

/// The directories airsegd.service lets the daemon write (ProtectSystem=strict): StateDirectory,
/// LogsDirectory and RuntimeDirectory. Kept equal to systemd/airsegd.service (a test compares them).
const std::vector<std::string>& unit_writable_dirs();

/// Warnings for --check-config: a configured path to write (state_dir, status.socket, autopilot.tlog.path
/// when enabled) outside unit_writable_dirs(). Valid for a run by hand, refused by the file system under
/// the unit.
std::vector<KeyProblem> unwritable_path_warnings(const Config& config);

}  // namespace airseg::daemon
