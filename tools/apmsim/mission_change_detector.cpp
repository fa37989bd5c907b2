#include "tools/apmsim/mission_change_detector.hpp"

#include <cmath>

namespace airseg::apmsim {

namespace {
constexpr int kMaxJumps = 64;                   // AP_Mission::get_next_cmd(): max_loops
constexpr std::uint16_t kNavSetYawSpeed = 213;  // MAV_CMD_NAV_SET_YAW_SPEED
constexpr std::uint16_t kNavScriptTime = 42702;
constexpr std::uint16_t kNavAttitudeTime = 42703;
}  // namespace

bool is_nav_command(std::uint16_t command) {
    return command <= kCmdNavLast || command == kNavSetYawSpeed || command == kNavScriptTime ||
           command == kNavAttitudeTime;
}

std::optional<std::uint16_t> next_cmd(const MissionStore& store, std::uint16_t start,
                                      std::span<const std::int32_t> jumps_done) {
    std::size_t index = start;
    for (int jumps = 0; jumps < kMaxJumps; ++jumps) {
        if (index >= store.count()) {
            return std::nullopt;
        }
        const StoredItem& item = store.at(index);
        if (item.command != kCmdDoJump) {
            return static_cast<std::uint16_t>(index);
        }
        const auto target = static_cast<long>(std::lround(item.param1));
        const auto repeats = static_cast<long>(std::lround(item.param2));
        if (target <= 0 || static_cast<std::size_t>(target) >= store.count()) {
            return std::nullopt;
        }
        const std::int32_t done = index < jumps_done.size() ? jumps_done[index] : 0;
        index = repeats < 0 || done < repeats ? static_cast<std::size_t>(target) : index + 1;
    }
    return std::nullopt;
}

std::optional<std::uint16_t> next_nav_cmd(const MissionStore& store, std::uint16_t start,
                                          std::span<const std::int32_t> jumps_done) {
    for (std::size_t index = start; index < store.count(); ++index) {
        const auto found = next_cmd(store, static_cast<std::uint16_t>(index), jumps_done);
        if (!found) {
            return std::nullopt;
        }
        if (is_nav_command(store.at(*found).command)) {
            return found;
        }
    }
    return std::nullopt;
}

bool MissionChangeDetector::check(const MissionStore& store, std::uint16_t current_nav,
                                  std::span<const std::int32_t> jumps_done) {
    const bool written = !primed_ || store.changes() != changes_;
    const bool moved = !primed_ || current_nav != current_;
    if (!written && !moved) {
        return false;
    }
    bool changed = false;
    std::size_t n = 0;
    std::uint16_t from = current_nav;
    while (n < kWatched) {
        const auto index = next_nav_cmd(store, from, jumps_done);
        if (!index) {
            break;
        }
        const Watched seen{*index, store.at(*index)};
        if (n >= count_ || !(watched_[n] == seen)) {
            changed = true;
        }
        watched_[n] = seen;
        ++n;
        from = static_cast<std::uint16_t>(*index + 1);
    }
    changed = changed || n != count_;
    primed_ = true;
    changes_ = store.changes();
    current_ = current_nav;
    count_ = n;
    return changed && !moved;
}

}  // namespace airseg::apmsim
