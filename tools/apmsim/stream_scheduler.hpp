#pragma once
// Telemetry rates: ArduPilot's stream groups (REQUEST_DATA_STREAM, stored in the SRn_* parameters) and
// per-message intervals (MAV_CMD_SET_MESSAGE_INTERVAL), which override the group rate of one message.
#include <cstdint>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

#include "base/time.hpp"

namespace airseg::apmsim {

/// MAV_DATA_STREAM ids ArduPilot serves.
enum class StreamGroup : std::uint8_t {
    All = 0,
    RawSensors = 1,
    ExtendedStatus = 2,
    RcChannels = 3,
    RawController = 4,
    Position = 6,
    Extra1 = 10,
    Extra2 = 11,
    Extra3 = 12,
};

/// The groups that have a rate of their own, with the SR0_ parameter suffix that stores it.
struct GroupInfo {
    StreamGroup group;
    std::string_view param_suffix;
};
const std::vector<GroupInfo>& stream_groups();
/// Message ids a group sends.
std::vector<std::uint32_t> group_messages(StreamGroup group);

class StreamScheduler {
  public:
    static constexpr double kMaxRateHz = 50.0;

    /// Sets a group's rate (0 stops it). Messages overridden by an interval keep their interval.
    void set_group_rate(StreamGroup group, double hz, TimePoint now);
    /// MAV_CMD_SET_MESSAGE_INTERVAL: a positive interval, `nullopt` for "back to the group rate", or a
    /// zero duration to stop the message.
    void set_message_interval(std::uint32_t msgid, std::optional<Duration> interval, TimePoint now);
    /// The interval a message goes out at now, or nothing if it does not.
    std::optional<Duration> interval_of(std::uint32_t msgid) const;

    /// Messages due at `now`, each once; their next time is scheduled.
    std::vector<std::uint32_t> take_due(TimePoint now);
    TimePoint next_due() const;
    /// Forgets every rate (a reboot; the driver reloads group rates from the parameters).
    void clear();

  private:
    struct Slot {
        std::optional<Duration> group_interval;
        std::optional<Duration> override_interval;  // zero: stopped
        TimePoint next = kNever;
    };
    void reschedule(std::uint32_t msgid, TimePoint now);

    std::map<StreamGroup, double> group_rates_;
    std::map<std::uint32_t, Slot> slots_;
};

}  // namespace airseg::apmsim
