#pragma once
// MissionClient: the ground side of the MAVLink mission protocol, sans-IO.
//
// Operations: full upload (MISSION_COUNT, then the items the vehicle requests), download
// (MISSION_REQUEST_LIST), partial write (MISSION_WRITE_PARTIAL_LIST), set current (MISSION_SET_CURRENT,
// confirmed by MISSION_CURRENT), clear (MISSION_CLEAR_ALL). Each is one work item with its own Step, a retry
// budget that is refreshed whenever the transfer makes progress, and exactly one Completion. Work items run
// one at a time, in the order they were queued.
//
// Timeouts follow the link: every answered first transmission is an RTT sample; the timeout is
// SRTT + 4 RTTVAR (RFC 6298), kept between min_timeout and max_timeout; before the first sample it doubles
// with each retransmission (Karn's rule), afterwards a retry waits twice the timeout (random loss, not
// congestion, is what a serial radio has). A fixed half-second timeout fails over a
// loaded 57600 radio; this one does not.
//
// The vehicle may ask for an item with MISSION_REQUEST or MISSION_REQUEST_INT. With use_int the answer is
// always MISSION_ITEM_INT (float degrees would cost decimetres); without it (APM 2.x), MISSION_ITEM to a
// MISSION_REQUEST. A download accepts either item form. A float MISSION_ITEM carries a float frame
// (MAV_FRAME_GLOBAL_RELATIVE_ALT 3 for 6, MAV_FRAME_GLOBAL 0 for 5): the *_INT frames belong to
// MISSION_ITEM_INT only, and a strict board refuses them in a MISSION_ITEM.
// Falling back (once per board, remembered until forget_board()): a board that refuses an upload answered
// with MISSION_ITEM_INT (any MISSION_ACK refusal, e.g. MAV_MISSION_UNSUPPORTED_FRAME), or that asks again
// and again for an item sent as MISSION_ITEM_INT without ever having taken one (a MAVLink-1-era board does
// not know the message and drops it), gets MISSION_ITEM and float requests from then on; the upload starts
// again. A refusal of the float form is final: the operation ends Denied with the board's answer.
// MAV_MISSION_ERROR before an upload's first request is final only when the vehicle says it again to the
// repeated MISSION_COUNT / MISSION_WRITE_PARTIAL_LIST: an item of an earlier transfer that reached the
// vehicle after that transfer had ended (a link outage, a stall of either end) is answered with the same
// ERROR, and such an answer can arrive just after the next request went out. MAV_MISSION_INVALID_SEQUENCE
// during an upload means a duplicate item crossed a request on the link; it is counted and the transfer goes
// on. MAV_MISSION_OPERATION_CANCELLED during an upload (the vehicle gave up on a bad link) starts the upload
// again, up to `retries` times in a row without an attempt getting further than the attempts before it.
//
// Contract: enqueue with upload()/download()/write_partial()/set_current()/clear(); feed every frame from the
// autopilot to handle_frame(); call handle_timeout(now) when poll_timeout() is due; after each input drain
// the shared Outbox and poll_completion().
#include <cstdint>
#include <deque>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/ardupilot/outbox.hpp"
#include "services/autopilot/autopilot_config.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "services/common/rtt_estimator.hpp"

namespace airseg::autopilot::ardupilot {

enum class MissionResult : std::uint8_t {
    Success,
    Timeout,          // retry budget spent without progress
    Denied,           // MAV_MISSION_DENIED / ERROR / UNSUPPORTED...
    NoSpace,          // MAV_MISSION_NO_SPACE
    InvalidArgument,  // refused before anything was sent (detail says why)
    Cancelled,        // cancel_all(): link down, reboot, shutdown
    Busy,             // too many operations queued
};
const char* to_string(MissionResult r);
std::ostream& operator<<(std::ostream& os, MissionResult r);

enum class MissionOperation : std::uint8_t { Upload, Download, WritePartial, SetCurrent, Clear };
const char* to_string(MissionOperation op);

struct MissionCompletion {
    std::uint32_t id = 0;
    MissionOperation operation = MissionOperation::Upload;
    MissionResult result = MissionResult::Success;
    std::string detail;
    std::vector<mavlink::MissionItemInt> items;  // Download: the whole mission, slot 0 (home) first
    std::optional<std::uint8_t> refusal{};       // Denied / NoSpace: the MAV_MISSION_RESULT the board sent
};

/// A partial write lands item by item: the board asks for an item only once it holds the one before it.
/// Items `first` .. `through - 1` of operation `id` are on the board.
struct MissionItemsStored {
    std::uint32_t id = 0;
    std::uint16_t first = 0;
    std::uint16_t through = 0;
};

struct MissionClientStats {
    std::uint64_t retransmissions = 0;
    std::uint64_t duplicate_requests = 0;  // the vehicle asked again for an item already sent
    std::uint64_t invalid_sequence_acks = 0;
    std::uint64_t ignored_frames = 0;      // mission frames that matched no running operation
    std::uint64_t restarts = 0;            // uploads started again after the vehicle cancelled them
    std::uint64_t float_fallbacks = 0;     // boards found not to take MISSION_ITEM_INT
    std::uint64_t stray_errors = 0;        // ERRORs answering an item repeated after its transfer ended
    std::uint64_t unconfirmed_errors = 0;  // ERRORs before a transfer's first request, not repeated when
                                           // the request was (an earlier transfer's answer, not a verdict)
};

class MissionClient {
  public:
    static constexpr std::size_t kMaxQueued = 16;
    /// A deadline found this late was missed because the daemon was not running: the answers waiting in the
    /// port get kReadGrace to be read before anything is sent again (once per deadline).
    static constexpr Duration kLateWake = milliseconds(250);
    static constexpr Duration kReadGrace = milliseconds(250);
    /// Repeated requests for an item answered as MISSION_ITEM_INT before a board that never took one is
    /// answered with MISSION_ITEM instead (a lost frame makes one repeat; three mean it is not understood).
    static constexpr unsigned kIntRepeatsBeforeFallback = 3;

    MissionClient(Outbox& outbox, std::uint8_t target_sysid, std::uint8_t target_compid,
                  MissionConfig config);

    std::uint32_t upload(std::vector<mavlink::MissionItemInt> items, TimePoint now);
    std::uint32_t download(TimePoint now);
    std::uint32_t write_partial(std::uint16_t first, std::vector<mavlink::MissionItemInt> items,
                                TimePoint now);
    std::uint32_t set_current(std::uint16_t seq, TimePoint now);
    std::uint32_t clear(TimePoint now);
    /// Ends every queued and running operation with Cancelled.
    void cancel_all(const std::string& why);

    /// Returns true when the frame belonged to the mission protocol (it may still have been ignored).
    bool handle_frame(const mavlink::Frame& frame, TimePoint now);
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;
    std::optional<MissionCompletion> poll_completion();
    /// The items of a running partial write the board has taken so far, as its requests show it (in order
    /// with the frames: poll after each one).
    std::optional<MissionItemsStored> poll_stored();

    bool idle() const { return work_.empty(); }
    /// Whether items go as MISSION_ITEM_INT (false after a fallback, or when configured so).
    bool answers_int() const { return use_int_; }
    /// Another board may be behind the port now: start again from the configured item form.
    void forget_board();
    /// Why the client answers with MISSION_ITEM although configured for MISSION_ITEM_INT ("" if it does not).
    const std::string& fallback_reason() const { return fallback_reason_; }
    /// The timeout from the RTT estimate alone.
    Duration base_timeout() const;

    std::optional<Duration> smoothed_rtt() const {
        return rtt_.samples() != 0 ? std::optional<Duration>(rtt_.srtt()) : std::nullopt;
    }
    const MissionClientStats& stats() const { return stats_; }

  private:
    enum class Step : std::uint8_t {
        NotStarted,
        WaitRequest,  // upload / partial: count or partial list sent, waiting for the vehicle's requests
        WaitAck,      // upload / partial: last item sent; clear: CLEAR_ALL sent
        WaitCount,    // download: REQUEST_LIST sent
        WaitItem,     // download: REQUEST for next_seq sent
        WaitCurrent,  // set current: SET_CURRENT sent, waiting for MISSION_CURRENT
    };
    struct WorkItem {
        std::uint32_t id = 0;
        MissionOperation op = MissionOperation::Upload;
        Step step = Step::NotStarted;
        std::vector<mavlink::MissionItemInt> items;
        std::uint16_t first = 0;     // partial write: first slot; set current: the slot
        std::uint16_t count = 0;     // download: items announced
        std::uint16_t next_seq = 0;  // upload: last item sent; download: next item wanted
        bool any_request = false;    // upload: the vehicle asked for at least one item
        unsigned attempt = 0;        // retries of the current step
        TimePoint deadline = kNever;
        bool read_grace = false;  // this deadline was already put off once for a late wake
        TimePoint sent_at{};
        bool retransmitted = false;  // Karn's rule: no RTT sample from a retransmission
        bool answer_int = true;      // reply form for the last request
        std::uint16_t highest_sent = 0;
        unsigned restarts = 0;              // upload / partial: restarts since the best seq last grew
        std::optional<std::uint16_t> best;  // upload / partial: highest seq requested by any attempt
        TimePoint last_progress{};          // the last fresh answer (refreshes the retry budget)
        TimePoint last_heard{};    // upload / partial: the last request of any kind for this transfer
        bool sent_int = false;     // upload / partial: this attempt answered with MISSION_ITEM_INT
        unsigned int_repeats = 0;  // requests repeated for an item answered as MISSION_ITEM_INT
        unsigned sends = 0;        // transmissions of any kind for this work item
        std::optional<unsigned> error_at_send;  // `sends` when an ERROR came before the first request
    };

    Duration current_timeout(const WorkItem& w) const;
    std::uint32_t enqueue(WorkItem item, TimePoint now);
    void start_front(TimePoint now);
    void transmit(WorkItem& w, TimePoint now, bool retry);
    void send_item(WorkItem& w, std::uint16_t seq, bool as_int);
    void progress(WorkItem& w, TimePoint now);
    void finish(MissionResult result, std::string detail, TimePoint now);
    void finish_download(TimePoint now);
    void restart(WorkItem& w, TimePoint now);
    void fall_back_to_float(WorkItem& w, const std::string& why, TimePoint now);
    void reject(MissionOperation op, std::uint32_t id, MissionResult r, std::string detail);

    void on_request(std::uint16_t seq, bool as_int, TimePoint now);
    void on_ack(std::uint8_t type, TimePoint now);
    void on_count(std::uint16_t count, TimePoint now);
    void on_item(const mavlink::MissionItemInt& item, TimePoint now);
    void on_current(std::uint16_t seq, TimePoint now);
    /// Sends `m` to the vehicle's mission (not its fence or rally points), addressed to the target.
    template <class M>
    void send_to_mission(M m);

    Outbox& out_;
    std::uint8_t target_sysid_;
    std::uint8_t target_compid_;
    MissionConfig config_;
    std::deque<WorkItem> work_;
    std::deque<MissionCompletion> done_;
    std::deque<MissionItemsStored> stored_;  // bounded: one per fresh request of the running write
    std::uint32_t next_id_ = 1;
    RttEstimator rtt_;
    unsigned backoff_ = 1;
    bool use_int_ = true;      // the item form this board is answered with
    bool int_proven_ = false;  // the board went on after an item sent as MISSION_ITEM_INT
    std::string fallback_reason_;
    std::optional<std::uint8_t> refusal_;  // the MISSION_ACK type ending the running operation
    // Items sent again for a repeated request whose answer has not come back yet. Each is answered once:
    // MAV_MISSION_ERROR if the vehicle had finished the transfer when it arrived, and that answer can reach
    // us after the next operation has begun.
    unsigned stray_items_ = 0;
    MissionClientStats stats_;
};

/// MISSION_ITEM (float degrees) as MISSION_ITEM_INT (degrees * 1e7), and back.
mavlink::MissionItemInt to_int_item(const mavlink::MissionItem& item);
mavlink::MissionItem to_float_item(const mavlink::MissionItemInt& item);

}  // namespace airseg::autopilot::ardupilot
