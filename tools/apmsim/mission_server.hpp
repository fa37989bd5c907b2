#pragma once
// The mission protocol as ArduPilot serves it (GCS_MAVLink of APM:Rover 2.x, with the MISSION_ACK results
// later firmware added):
//  - download: MISSION_REQUEST_LIST → MISSION_COUNT; each MISSION_REQUEST(_INT) → MISSION_ITEM(_INT).
//    Item 0 is always the board's home. Nothing is retried by the board; the GCS drives the download.
//  - upload: MISSION_COUNT n → NO_SPACE beyond capacity; else the board requests items 0..n-1 in order with
//    MISSION_REQUEST, re-requests the expected item after `rerequest` without progress, and gives up after
//    `give_up` of silence (MISSION_ACK OPERATION_CANCELLED). The last item is answered with MISSION_ACK
//    ACCEPTED and the stored mission is cut to n items. An item out of order gets INVALID_SEQUENCE and the
//    transfer goes on. While one GCS uploads, another one's MISSION_COUNT, list request or partial write
//    is DENIED; the same GCS sending MISSION_COUNT again restarts its upload.
//  - partial write: MISSION_WRITE_PARTIAL_LIST start..end (end may equal the count: append one) → the same
//    request loop for those items; the rest of the mission stays.
//  - clear all: refused (ERROR) while a mission is running in AUTO, as AP_Mission refuses it; else home
//    stays and everything else goes.
//  - set current: MISSION_SET_CURRENT seq < count → hook, then MISSION_CURRENT as confirmation.
//  - MISSION_ITEM with current == 2 is a "fly to here" in GUIDED mode (ArduPilot's guided waypoint).
// Uploaded items are written as they arrive (the board writes each to EEPROM); the target being driven to is
// a copy held by the navigation, so replacing items does not move it.
#include <cstdint>
#include <functional>
#include <optional>

#include "base/time.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "tools/apmsim/mission_store.hpp"
#include "tools/apmsim/outbox.hpp"

namespace airseg::apmsim {

/// MAV_MISSION_RESULT values.
enum class MissionResult : std::uint8_t {
    Accepted = 0,
    Error = 1,
    Unsupported = 3,
    NoSpace = 4,
    InvalidSequence = 13,
    Denied = 14,
    OperationCancelled = 15,
};

struct MissionHooks {
    /// The current item changed by request; returns false to refuse.
    std::function<bool(std::uint16_t seq)> set_current;
    /// Whether a mission is running (then clear-all is refused).
    std::function<bool()> running;
    /// Stored items changed (after an upload, partial write or clear).
    std::function<void()> changed;
    /// A guided "go to" location arrived; returns false to refuse (not in GUIDED).
    std::function<bool(const StoredItem&)> guided_goto;
    /// The home location to report as item 0.
    std::function<StoredItem()> home;
    /// The current item, for the `current` flag of downloaded items.
    std::function<std::uint16_t()> current;
};

struct MissionServerStats {
    std::uint64_t uploads_completed = 0;
    std::uint64_t uploads_cancelled = 0;
    std::uint64_t rerequests = 0;
    std::uint64_t items_sent = 0;
    std::uint64_t items_received = 0;
    std::uint64_t denied = 0;
};

class MissionServer {
  public:
    MissionServer(MissionStore& store, Outbox& out, MissionHooks hooks, Duration rerequest = seconds(1),
                  Duration give_up = seconds(8))
        : store_(store), out_(out), hooks_(std::move(hooks)), rerequest_(rerequest), give_up_(give_up) {}

    /// Handles a mission message; false if `frame` is not one.
    bool handle(const mavlink::Frame& frame, TimePoint now);
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;
    /// A reboot forgets any transfer in progress.
    void reset() { upload_.reset(); }

    bool receiving() const { return upload_.has_value(); }
    const MissionServerStats& stats() const { return stats_; }

  private:
    struct Upload {
        std::uint8_t sysid = 0;
        std::uint8_t compid = 0;
        std::uint16_t next = 0;  // the item requested
        std::uint16_t end = 0;   // one past the last item of the transfer
        bool partial = false;
        TimePoint last_heard{};
        TimePoint last_request{};
    };

    void on_request_list(const mavlink::Frame& f);
    void on_request(const mavlink::Frame& f, std::uint16_t seq, bool as_int);
    void on_count(const mavlink::Frame& f, std::uint16_t count, TimePoint now);
    void on_partial(const mavlink::Frame& f, std::int16_t start, std::int16_t end, TimePoint now);
    void on_item(const mavlink::Frame& f, std::uint16_t seq, std::uint8_t current, const StoredItem& item,
                 TimePoint now);
    void on_clear(const mavlink::Frame& f);
    void on_set_current(std::uint16_t seq);
    void request_next(TimePoint now);
    void ack(const mavlink::Frame& to, MissionResult result);
    void ack(std::uint8_t sysid, std::uint8_t compid, MissionResult result);
    bool other_uploader(const mavlink::Frame& f) const;

    MissionStore& store_;
    Outbox& out_;
    MissionHooks hooks_;
    Duration rerequest_;
    Duration give_up_;
    std::optional<Upload> upload_;
    MissionServerStats stats_;
};

}  // namespace airseg::apmsim
