#pragma once
#include <string>

namespace airseg::daemon {

/// Sets up spdlog for the daemon. Under systemd (JOURNAL_STREAM set, stderr connected to the journal) each
/// line starts with the syslog priority "<N>" so journald keeps the level; on a terminal, colour console
/// output.
void setup_logging(const std::string& level);

/// Changes the level at run time (SIGHUP). Returns false for an unknown level name.
bool set_log_level(const std::string& level);

/// True when stderr is the journal stream systemd gave us.
bool stderr_is_journal();

}  // namespace airseg::daemon
