#pragma once
// Statistics of a running emulator, as text for people and as JSON for scripts and tests.
#include <array>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "tools/linksim/radio_model.hpp"

namespace airseg::linksim {

/// What the emulator adds to the model's counters, per side (the host at that pty).
struct HostStats {
    bool peer_connected = false;
    std::uint64_t backlog_dropped = 0;  ///< read from the pty while the emulator's backlog was full
    std::uint64_t not_written = 0;  ///< delivered by the radio while nobody had the pty open (or queue full)
};

nlohmann::json stats_json(const RadioModel& model, const std::array<HostStats, 2>& hosts, TimePoint now);
std::string stats_text(const RadioModel& model, const std::array<HostStats, 2>& hosts, TimePoint now);

}  // namespace airseg::linksim
