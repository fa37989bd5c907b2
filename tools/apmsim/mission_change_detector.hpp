#pragma once
// How current ArduPilot walks a stored mission and notices that it changed under a running AUTO, sans-IO:
//  - next_cmd() / next_nav_cmd(): AP_Mission::get_next_cmd() and get_next_nav_cmd() without counting a
//    jump: a DO_JUMP is followed while it has repeats left by the jump counters given (-1: forever), at most
//    64 times; a jump to item 0 or past the end ends the search. get_next_nav_cmd() goes on from the index
//    after the one it started from, not after the item a jump led to (so a jump landing on a do-command is
//    stepped over from where the search began, as in AP_Mission.cpp).
//  - MissionChangeDetector: AP_Mission_ChangeDetector. It keeps the current navigation command and the next
//    two (jumps followed) as they were at its last look, and looks again only when the mission was written
//    (MissionStore::changes()) or the current navigation command moved. A difference in those three commands
//    is a change, unless the current command moved in the same look (then the new ones are only noted).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "tools/apmsim/mission_store.hpp"

namespace airseg::apmsim {

/// AP_Mission::is_nav_cmd(): ids up to MAV_CMD_NAV_LAST, and the three later navigation commands.
bool is_nav_command(std::uint16_t command);

/// The index of the first command at or after `start` that is not a DO_JUMP, following the jumps that
/// have repeats left by `jumps_done` (indexed by item; missing entries count 0).
std::optional<std::uint16_t> next_cmd(const MissionStore& store, std::uint16_t start,
                                      std::span<const std::int32_t> jumps_done);
/// The index of the next navigation command at or after `start`, jumps followed as next_cmd() does.
std::optional<std::uint16_t> next_nav_cmd(const MissionStore& store, std::uint16_t start,
                                          std::span<const std::int32_t> jumps_done);

class MissionChangeDetector {
  public:
    static constexpr std::size_t kWatched = 3;  // mis_change_detect_cmd_max

    /// AP_Mission_ChangeDetector::check_for_mission_change(): true when one of the watched commands changed
    /// while the current navigation command (`current_nav`) stayed. Called with nothing changed since the
    /// last call it only compares two numbers.
    bool check(const MissionStore& store, std::uint16_t current_nav,
               std::span<const std::int32_t> jumps_done);
    /// Forgets what it saw: the next check() takes the mission as it is without reporting a change.
    void reset() { primed_ = false; }

  private:
    struct Watched {
        std::uint16_t index = 0;
        StoredItem item;
        bool operator==(const Watched&) const = default;
    };

    bool primed_ = false;
    std::uint64_t changes_ = 0;
    std::uint16_t current_ = 0;
    std::size_t count_ = 0;
    std::array<Watched, kWatched> watched_{};
};

}  // namespace airseg::apmsim
