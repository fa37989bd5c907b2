#pragma once
// Internal state of Transport (see transport.hpp for the contract). Split over transport.cpp (public calls,
// timers, link state), transport_rx.cpp (frames in, handshake) and transport_tx.cpp (scheduler, frames out).
#include <array>
#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "services/common/rtt_estimator.hpp"
#include "services/groundlink/transport/air_estimate.hpp"
#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/erasure_code.hpp"
#include "services/groundlink/transport/error_rate_meter.hpp"
#include "services/groundlink/transport/fast_queue.hpp"
#include "services/groundlink/transport/fast_reassembly.hpp"
#include "services/groundlink/transport/fec_frame.hpp"
#include "services/groundlink/transport/fec_plan.hpp"
#include "services/groundlink/transport/frame.hpp"
#include "services/groundlink/transport/frame_mac.hpp"
#include "services/groundlink/transport/replay_window.hpp"
#include "services/groundlink/transport/safe_receiver.hpp"
#include "services/groundlink/transport/safe_sender.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

/// Bytes/s moving average with a 1 s time constant: `rate` was last updated at `then`.
inline double decayed_rate(double rate, TimePoint then, TimePoint now) {
    const double dt = std::chrono::duration<double>(now - then).count();
    return dt > 0.0 ? rate * std::exp(-dt) : rate;
}

/// The core's deadlines; poll_timeout() is the earliest of them.
enum class Timer : std::uint8_t { Transmit, Retransmit, Reassembly, Liveness, Count };

class Transport::Impl {
  public:
    static constexpr std::size_t kEventCap = 64;
    static constexpr std::size_t kMirrorCap = 4;
    static constexpr unsigned kMaxBackoff = 10;

    Impl(TransportConfig config, TimePoint now);

    // transport.cpp
    SendResult send_safe(std::uint8_t priority, std::span<const std::uint8_t> msg, TimePoint now);
    SendResult send_fast(std::uint8_t priority, std::uint16_t topic, std::span<const std::uint8_t> msg,
                         TimePoint now);
    void handle_timeout(TimePoint now);
    void push_event(TransportEvent::Kind kind, std::size_t path = 0, std::uint64_t count = 0);
    void update_link_state();
    void refresh(TimePoint now);
    /// The part of refresh() that time and the air budget move: enough after an input that completed no
    /// frame (the Safe windows, the reassembly and the error rate are as they were).
    void refresh_transmit(TimePoint now);
    /// The fields of stats() that mirror state (link, timing, sizes, queues), as of the latest input: taken
    /// when stats() is asked for rather than after every input.
    void snapshot_stats();

    // transport_rx.cpp
    void handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes, TimePoint now);
    void count_key_mismatch(std::span<const std::uint8_t> plain, bool keyed, frame::Kind kind);
    /// `wire_bytes`: the frame's size on the wire for the error meter (0: rebuilt from shards, not counted).
    void on_plain_frame(std::size_t path, std::span<const std::uint8_t> plain, std::size_t wire_bytes,
                        TimePoint now);
    void on_shard(std::size_t path, std::span<const std::uint8_t> plain, std::size_t wire_bytes,
                  TimePoint now);
    void on_hello(std::size_t path, const frame::Hello& h, std::size_t key, TimePoint now);
    void on_data_frame(std::span<const std::uint8_t> frame, TimePoint now);
    void on_authentic(std::size_t path, std::uint8_t peer_heard_mask, TimePoint now);
    void on_safe(const frame::SafeChunk& c, TimePoint now);
    void on_fast(const frame::FastChunk& c, TimePoint now);
    void on_ack(const frame::AckChunk& a, TimePoint now);
    void accept_session(std::uint64_t peer, std::size_t key, TimePoint now);
    void queue_hello_reply(const frame::Hello& h, std::size_t key);
    std::uint64_t fresh_nonce();

    // transport_tx.cpp
    std::optional<std::vector<std::uint8_t>> poll_transmit(std::size_t path, TimePoint now);
    [[nodiscard]] bool carries_data(std::size_t path) const;
    [[nodiscard]] bool keeps_alive(std::size_t path) const;
    [[nodiscard]] TimePoint probe_deadline(std::size_t path) const;
    [[nodiscard]] bool probe_owed(std::size_t path, TimePoint now) const;
    [[nodiscard]] bool peer_mask_fresh() const;
    [[nodiscard]] std::uint8_t heard_mask() const;
    [[nodiscard]] std::uint8_t header_flags() const;
    [[nodiscard]] bool may_borrow(std::size_t path) const;
    /// More than kLossyFraction of the recent Safe segments were declared lost.
    [[nodiscard]] bool lossy() const;
    /// Split mode: `path` is the peer's transmit pair, used for bulk while the own pair works.
    [[nodiscard]] bool borrowed(std::size_t path) const;
    [[nodiscard]] Duration reorder_slack() const;
    /// Any Safe or Fast traffic ready; `bulk`: include the lowest priority.
    [[nodiscard]] bool data_ready(bool bulk) const {
        const std::size_t levels = bulk ? senders.size() : senders.size() - 1;
        for (std::size_t l = 0; l < levels; ++l) {
            if (level_ready(l, true)) {
                return true;
            }
        }
        return false;
    }
    /// Half-duplex air gate of a path: open; only urgent (non-bulk) traffic, for an end using less than half
    /// the air while the peer has urgent traffic; closed until the shared budget is paid (or, with a known
    /// radio buffer, until the radio's queue has room).
    enum class AirGate : std::uint8_t { Open, UrgentOnly, Closed };
    [[nodiscard]] AirGate air_gate(std::size_t path) const;
    /// When a closed air gate may open again.
    [[nodiscard]] TimePoint air_reopens(std::size_t path) const;
    /// Bytes/s this end writes on a path, recently (what the air gate compares with its shares).
    [[nodiscard]] double air_use(std::size_t path) const;
    /// The radio's own queue is estimated past half its buffer.
    [[nodiscard]] bool radio_full(std::size_t path) const;
    /// Bytes per second the air carries as configured (air_rate, else link_rate).
    [[nodiscard]] double configured_air_rate() const {
        return cfg.air_rate_bytes_per_s > 0.0 ? cfg.air_rate_bytes_per_s : cfg.link_rate_bytes_per_s;
    }
    /// Bytes per second the air carries as pacing takes it: measured with air_adapt, else configured.
    [[nodiscard]] double air_rate() const { return air_rate_now; }
    /// Feeds a round trip to the air measurement, with the time its two frames take without turnaround.
    void measure_round_trip(Duration rtt_sample, std::size_t segment_bytes, TimePoint now);
    /// Closes a measurement period when due and, with air_adapt, follows the new figures.
    void follow_air(TimePoint now);
    /// Payload bytes per second the link carries (TransportConfig::carried_rate_bytes_per_s()).
    [[nodiscard]] double carried_rate() const { return carried; }
    /// Time `bytes` written as one frame occupy the link: the serial port's time or the air's with each air
    /// packet's overhead, whichever is longer; `scale` below 1 paces slower.
    [[nodiscard]] Duration frame_time(std::size_t bytes, double scale = 1.0) const {
        return frame_time_at(bytes, air_rate(), scale);
    }
    /// The same at the configured air rate: the bytes' own time, whatever else the air loses.
    [[nodiscard]] Duration configured_frame_time(std::size_t bytes) const {
        return frame_time_at(bytes, configured_air_rate(), 1.0);
    }
    [[nodiscard]] Duration frame_time_at(std::size_t bytes, double rate, double scale) const;
    /// Air time of `bytes` heard from the peer (a read is not a frame: overhead in proportion).
    [[nodiscard]] Duration heard_air_time(std::size_t bytes) const;
    [[nodiscard]] TimePoint ack_due() const;
    [[nodiscard]] TimePoint content_due(std::size_t path) const;
    [[nodiscard]] std::size_t payload_cap() const;
    // Inline: every deadline computation asks them for each level.
    [[nodiscard]] bool level_ready(std::size_t level, bool retx_ok) const {
        if ((bulk_blocked && level + 1 == senders.size()) || (bulk_only && level + 1 < senders.size())) {
            return false;
        }
        return !fast[level].empty() || (retx_ok && senders[level].has_lost()) ||
               senders[level].can_send_new();
    }
    std::optional<std::vector<std::uint8_t>> build_hello(std::size_t path, TimePoint now);
    std::optional<std::vector<std::uint8_t>> build_data(std::size_t path, TimePoint now);
    bool add_data_chunk(std::vector<frame::Chunk>& chunks, std::vector<std::vector<std::uint8_t>>& storage,
                        std::size_t& room, bool first, TimePoint now);
    void account_sent(std::size_t path, std::size_t bytes, TimePoint now);
    /// Seals a frame and encodes it for the wire: one COBS frame, or shards with parity under the FEC plan.
    std::vector<std::uint8_t> to_wire(std::vector<std::uint8_t> plain, const FrameMac* key,
                                      const MacContext& ctx);
    /// The byte error rate this end's frames meet: the peer's report, or until one arrives this end's own
    /// measurement (radio links are mostly symmetric); nullopt when neither exists.
    [[nodiscard]] std::optional<double> tx_error_rate() const;
    void update_plan();
    void mark_urgent(TimePoint now) { urgent_until = now + cfg.latency_hold; }

    TransportConfig cfg;
    AirEstimate air_estimate;
    double air_rate_now = configured_air_rate();
    double carried = cfg.carried_rate_bytes_per_s();  // asked at every air gate: computed once
    std::size_t frame_wire_bytes = 0;                 // of the frame being read (its acks' round trips)
    // keys[0] from TransportConfig::key, keys[1] from second_key. `mac` is the session's key (keys[0] until a
    // handshake authenticated with keys[1] is accepted); null on an unkeyed link.
    std::array<std::unique_ptr<FrameMac>, 2> keys;
    FrameMac* mac = nullptr;
    std::size_t session_key = 0;
    std::size_t hello_reply_key = 0;
    std::uint64_t unestablished_hellos = 0;  // alternates the key of hellos sent before any session
    LinkStats stats;
    TimePoint current_time;

    // Session (handshake in docs/ground-link.md, "Sessions").
    std::uint64_t nonce_counter = 0;
    std::uint64_t candidate = 0;  // offered in the next handshake
    bool established = false;
    bool confirmed = false;  // the peer is known to hold the same session
    std::uint64_t my_nonce = 0;
    std::uint64_t peer_nonce = 0;
    std::uint64_t last_seen_peer = 0;
    // Hellos sent without a session since last_seen_peer was learnt. A nonce learnt from a recording, or one
    // the peer has since replaced, is never answered; after a few tries the hellos echo nothing instead,
    // which any peer answers with a challenge.
    unsigned unanswered_hellos = 0;
    std::optional<frame::Hello> hello_reply;
    std::uint8_t hello_reply_paths = 0;
    std::uint64_t next_frame_number = 0;
    ReplayWindow rx_window;

    struct Path {
        explicit Path(std::size_t max_encoded) : deframer(max_encoded) {}
        CobsDeframer deframer;
        TimePoint next_free{};  // pacing: the path's byte-time budget allows the next frame from here
        TimePoint last_sent{};
        TimePoint next_hello{};
        TimePoint last_hello{};
        TimePoint last_heard{};
        std::size_t streak = 0;
        bool alive = false;
        std::deque<std::vector<std::uint8_t>> mirror;  // redundant mode: frames built for another path
        double rx_rate = 0.0;                          // bytes/s heard on the path, moving average over ~1 s
        TimePoint rx_rate_time{};
        TimePoint air_debt{};  // half duplex: air budget of both ends together
        // When this end's radio would have sent all it was given: its own frames at the air's pace, held
        // back by the peer's air time while it holds any (the radio's queue, for radio_buffer).
        TimePoint own_air_debt{};
        double tx_rate = 0.0;  // bytes/s written to the path, same average
        TimePoint tx_rate_time{};
        std::size_t last_frame = 0;  // bytes of the latest frame written
        // The last good shard heard (group, index) and the damaged frames heard since: a gap in a group's
        // indices beyond those is shards that never arrived (lost whole, with an air packet).
        std::optional<fec::ShardId> last_shard;
        std::size_t bad_since_shard = 0;
    };
    std::vector<Path> paths;
    std::uint8_t peer_mask = 0;
    bool peer_urgent = false;
    TimePoint peer_mask_time{};
    bool peer_mask_known = false;
    bool link = false;

    struct AckState {
        bool needed = false;
        bool immediate = false;
        std::size_t unacked = 0;
        TimePoint first{};
    };
    std::vector<SafeSender> senders;
    std::vector<SafeReceiver> receivers;
    std::vector<AckState> acks;
    std::vector<unsigned> backoff;
    std::vector<FastQueue> fast;
    FastReassembly reassembly;
    RttEstimator rtt;

    // Scheduler.
    std::array<double, kMaxPriorities> share_credit{};
    double retx_credit = 0.0;
    std::array<bool, kMaxPriorities> fast_turn{};
    TimePoint urgent_until{};
    bool bulk_blocked = false;  // while filling a frame through an urgent_only gate
    bool bulk_only = false;     // while filling a frame for a borrowed path
    double sent_window = 0.0;
    double lost_window = 0.0;

    // Frame size adaptation and forward error correction.
    ErrorRateMeter meter;
    std::size_t damaged_since_numbered = 0;  // damaged frames heard since the last data frame read whole
    std::optional<std::uint32_t> last_reported_ppm;  // in report units, bursty flag included
    TimePoint last_report_time{};
    bool shards_heard_since_report = false;
    std::optional<double> peer_error;  // the peer's latest report
    bool peer_bursty = false;
    std::optional<double> plan_rate;  // the rate `plan` was made for
    bool plan_bursty = false;
    fec::FramePlan plan;
    std::array<std::uint16_t, fec::kMaxShards + 1>
        parity_cache{};  // by data shards, for plan; 0xFFFF unknown
    std::uint8_t next_group = 0;
    fec::ShardAssembler shards;
    std::vector<std::uint8_t> rebuilt;  // a frame rebuilt from shards

    // build_data's scratch: the chunks of the frame being filled, the bytes they point into, the channels it
    // acknowledges.
    std::vector<frame::Chunk> tx_chunks;
    std::vector<std::vector<std::uint8_t>> tx_storage;
    std::vector<std::size_t> tx_acked;

    std::deque<Delivered> deliveries;
    std::deque<TransportEvent> events;
    std::array<TimePoint, static_cast<std::size_t>(Timer::Count)> timers{};
    // When refresh() last ran: the timers describe the state as of then, until any input changes it.
    TimePoint refreshed_at{};
    TimePoint earliest = kNever;  // the earliest of the timers: poll_timeout()
};

}  // namespace airseg::groundlink
