#pragma once
// The board's stored mission (its EEPROM): item 0 is home, items 1.. are the plan. Survives reboots.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "services/autopilot/mavlink/enums.hpp"

namespace airseg::apmsim {

/// MAV_CMD values the simulator acts on; every other command is stored and skipped when reached.
inline constexpr std::uint16_t kCmdNavWaypoint = 16;
inline constexpr std::uint16_t kCmdNavLoiterUnlimited = 17;
inline constexpr std::uint16_t kCmdNavLoiterTurns = 18;
inline constexpr std::uint16_t kCmdNavLoiterTime = 19;
inline constexpr std::uint16_t kCmdNavReturnToLaunch = 20;
inline constexpr std::uint16_t kCmdNavTakeoff = 22;
inline constexpr std::uint16_t kCmdNavLast = 95;  // MAV_CMD_NAV_LAST: ids below are navigation commands
inline constexpr std::uint16_t kCmdConditionDelay = 112;
inline constexpr std::uint16_t kCmdConditionChangeAlt = 113;
inline constexpr std::uint16_t kCmdConditionDistance = 114;
inline constexpr std::uint16_t kCmdConditionLast = 159;  // MAV_CMD_CONDITION_LAST
inline constexpr std::uint16_t kCmdDoJump = 177;         // param1: target item, param2: repeats (-1: forever)
using mavlink::kCmdDoChangeSpeed;  // param1: speed type, param2: m/s, param3: throttle %

struct StoredItem {
    std::uint16_t command = kCmdNavWaypoint;
    std::uint8_t frame = 3;  // MAV_FRAME_GLOBAL_RELATIVE_ALT
    std::uint8_t autocontinue = 1;
    float param1 = 0, param2 = 0, param3 = 0, param4 = 0;
    std::int32_t lat_e7 = 0;
    std::int32_t lon_e7 = 0;
    float alt = 0;

    /// Commands the rover drives to (a location to reach).
    bool is_location() const {
        return command == kCmdNavWaypoint || command == kCmdNavLoiterUnlimited ||
               command == kCmdNavLoiterTurns || command == kCmdNavLoiterTime;
    }
    bool operator==(const StoredItem&) const = default;
};

class MissionStore {
  public:
    explicit MissionStore(std::size_t capacity, StoredItem home) : capacity_(capacity), items_{home} {}

    /// Items the board can hold, home included.
    std::size_t capacity() const { return capacity_; }
    /// Items stored, home included (what MISSION_COUNT reports); never below 1.
    std::size_t count() const { return items_.size(); }
    const StoredItem& at(std::size_t seq) const { return items_.at(seq); }
    const std::vector<StoredItem>& items() const { return items_; }

    /// Writes item `seq`, appending when seq == count(). False when seq is past the end or capacity.
    bool write(std::size_t seq, const StoredItem& item) {
        if (seq > items_.size() || seq >= capacity_) {
            return false;
        }
        if (seq == items_.size()) {
            items_.push_back(item);
        } else {
            items_[seq] = item;
        }
        ++changes_;
        return true;
    }
    /// Makes the mission exactly `count` items (at least home): keeps the first ones, fills new slots with
    /// `blank`.
    void resize(std::size_t count, const StoredItem& blank) {
        items_.resize(std::max<std::size_t>(1, std::min(count, capacity_)), blank);
        ++changes_;
    }
    /// Keeps the first `count` items (home always stays).
    void truncate(std::size_t count) {
        if (count >= 1 && count < items_.size()) {
            items_.resize(count);
            ++changes_;
        }
    }
    void set_home(const StoredItem& home) { items_[0] = home; }
    /// Counts every write (AP_Mission's last change time: an item written, even with the same content, or
    /// the mission cut shorter).
    std::uint64_t changes() const { return changes_; }

  private:
    std::size_t capacity_;
    std::vector<StoredItem> items_;
    std::uint64_t changes_ = 0;
};

}  // namespace airseg::apmsim
