#pragma once
// ParamCache: the autopilot's parameters as the hub has seen them go by (every PARAM_VALUE the vehicle
// forwards, with its param_count and param_index), so that a ground station's PARAM_REQUEST_LIST or
// PARAM_REQUEST_READ is answered at once from the ground instead of over the radio.
//
// Fresh means: every index 0 .. param_count - 1 has been seen since the cache was last reset, and no value
// changes are outstanding. The cache is reset (emptied) when the vehicle's link session starts anew (its
// airsegd restarted), after an outage of the link longer than kOutageKept (the hub decides; the vehicle
// queues parameter values through a shorter one), when the autopilot reboots (its time since boot goes
// back in the frames forwarded, compared message by message, since the link may deliver one message's older
// value after another's newer one; or the vehicle says so in its event, which comes whatever is forwarded),
// and when a PARAM_VALUE announces another param_count. A PARAM_SET a station sends marks its parameter
// outstanding until the autopilot's PARAM_VALUE echo comes back; meanwhile requests go over the radio.
// Sans-IO: frames in, frames out.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::ground {

struct ParamCacheStats {
    std::uint64_t values = 0;        // PARAM_VALUEs taken in
    std::uint64_t overflow = 0;      // values beyond kMaxEntries (or of a param_count above it), not kept
    std::uint64_t other_source = 0;  // values from another system or component than the cached one, ignored
    std::uint64_t resets = 0;
    std::uint64_t reboots = 0;         // autopilot reboots seen
    std::uint64_t answered_lists = 0;  // PARAM_REQUEST_LISTs answered from the cache
    std::uint64_t answered_reads = 0;  // PARAM_REQUEST_READs answered from the cache
    std::uint64_t passed_on = 0;       // requests the cache could not answer (sent to the vehicle)
    std::size_t entries = 0;
    std::size_t count = 0;  // param_count the autopilot announced; 0 before the first value
};

class ParamCache {
  public:
    /// Parameters kept at most (ArduPilot Rover has about 280 to 900, Copter about 1,200).
    static constexpr std::size_t kMaxEntries = 4096;
    /// A link outage longer than this empties the cache (see above).
    static constexpr auto kOutageKept = std::chrono::seconds(60);
    /// A time since boot this much earlier than the last one means the autopilot rebooted.
    static constexpr std::uint32_t kRebootBackstepMs = 2000;

    /// A frame from the vehicle (any message: PARAM_VALUE is kept, time since boot watched).
    void from_vehicle(const mavlink::Frame& frame, std::span<const std::uint8_t> bytes);
    /// A frame from a ground station. For a request the cache can answer, the answer's frames (the
    /// autopilot's PARAM_VALUEs as they came) and true; otherwise false and the frame goes to the vehicle.
    bool answer(const mavlink::Frame& frame, std::vector<std::uint8_t>& out);
    void reset();
    /// The vehicle said its autopilot rebooted (its "autopilot rebooted: ..." event). One reboot told twice
    /// (by the time since boot, then by the event) with no value between empties the cache once.
    void autopilot_rebooted();

    [[nodiscard]] bool fresh() const;
    [[nodiscard]] ParamCacheStats stats() const;

  private:
    struct Entry {
        std::string id;
        std::vector<std::uint8_t> bytes;  // the PARAM_VALUE frame as the autopilot sent it
    };
    bool addressed_to_source(std::uint8_t system, std::uint8_t component) const;
    void watch_boot_time(const mavlink::Frame& frame);
    void store(const std::string& id, std::size_t index, std::span<const std::uint8_t> bytes);

    std::optional<std::pair<std::uint8_t, std::uint8_t>> source_;  // the autopilot's system, component
    std::size_t count_ = 0;
    std::vector<std::optional<Entry>> by_index_;
    std::map<std::string, std::size_t> index_of_;
    std::set<std::string> outstanding_;  // PARAM_SETs not yet echoed
    std::size_t held_ = 0;
    std::map<std::uint32_t, std::uint32_t> boot_ms_;  // the last time since boot, by message id
    bool emptied_for_reboot_ = false;                 // no value came since a reboot emptied the cache
    ParamCacheStats stats_;
};

}  // namespace airseg::ground
