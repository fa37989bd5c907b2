#pragma once
// The ground-link transport core: a sans-IO protocol engine for one end of the air↔ground serial link.
// Byte layouts, state machines, timers and every parameter are described in docs/ground-link.md.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "base/time.hpp"

namespace airseg::groundlink {

inline constexpr std::size_t kMaxPaths = 2;
inline constexpr std::size_t kMaxPriorities = 8;
inline constexpr std::size_t kKeyBytes = 32;
inline constexpr std::size_t kMaxFragments = 255;
/// Largest Safe window: the selective-acknowledgement bitmap covers this many segments.
inline constexpr std::size_t kMaxSafeWindow = 128;

/// How the core spreads traffic over its paths (serial radio pairs).
enum class PathMode : std::uint8_t {
    Single,     ///< one path carries both directions
    Split,      ///< each end transmits on its own path (split_tx_path); falls back to the other when it goes
                ///< silent
    Redundant,  ///< every frame goes on every live path; the receiver drops the duplicates
};

enum class MessageClass : std::uint8_t {
    Safe,  ///< exactly once, in order per priority channel, retransmitted until acknowledged
    Fast,  ///< best effort, freshest value wins per topic, never retransmitted
};

/// Every field has its YAML key (under `groundlink.transport`) next to it. Durations are std::chrono
/// durations.
struct TransportConfig {
    /// link_rate: bytes/s the core may write to each path (pacing); 57600 baud is about 5760 B/s.
    double link_rate_bytes_per_s = 5760.0;
    /// paths: 1 or 2 serial radio pairs.
    std::size_t paths = 1;
    /// path_mode: single | split | redundant.
    PathMode path_mode = PathMode::Single;
    /// split_tx_path: this end's transmit path in split mode (the peer configures the other one).
    std::size_t split_tx_path = 0;
    /// split_borrow: in split mode, also send on the peer's transmit path while the peer leaves it mostly
    /// idle (under a quarter of link_rate) and has no urgent traffic, so one-way bulk uses both pairs.
    bool split_borrow = true;
    /// half_duplex: both ends share one air budget per path (the radios of a pair share their air time).
    bool half_duplex = true;
    /// air_turnaround: air time a half-duplex radio pair loses when the sending side changes; every frame
    /// heard costs the air budget two of them.
    Duration air_turnaround = std::chrono::milliseconds(1);
    /// air_rate: bytes/s the radios carry on air, when it differs from what the serial port takes (a SiK
    /// radio at 64 kbit/s air speed behind a 57600 baud port); 0 = link_rate. Frames are paced by the slower
    /// of the two.
    double air_rate_bytes_per_s = 0.0;
    /// air_packet: payload bytes per air packet (0 = the air is not cut into packets); each packet costs
    /// air_packet_overhead bytes more of air time (preamble, sync word, header, CRC).
    std::size_t air_packet_payload = 0;
    std::size_t air_packet_overhead = 0;
    /// radio_buffer: bytes the local radio holds before they go on air (0 = unknown): the core keeps its
    /// estimate of what waits in the radio under half of it, so the radio never drops bytes for a full
    /// buffer.
    std::size_t radio_buffer_bytes = 0;
    /// air_adapt: pace to the air as measured from the link's own traffic (LinkStats::air_carried), between
    /// a quarter of the configured carried rate and that rate. The measurement runs (and is reported)
    /// either way.
    bool air_adapt = false;

    /// max_frame_payload: chunk bytes per frame on a clean link.
    std::size_t max_frame_payload = 1024;
    /// min_frame_payload: floor of the adaptive frame size.
    std::size_t min_frame_payload = 16;
    /// adaptive_frame_size: size frames for the byte error rate the peer measures (and reports) on this end's
    /// frames: the goodput-optimal length, or forward error correction where it carries more.
    bool adaptive_frame_size = true;
    /// fec: cut frames into shards with Reed–Solomon parity when the error rate makes it pay (needs
    /// adaptive_frame_size). Shards are always decoded, whatever this says.
    bool fec = true;
    /// latency_frame_payload: frame ceiling while Fast or non-bulk traffic is active (or frame loss is
    /// heavy), so a frame already on the air holds an urgent message back by at most this many bytes of air
    /// time.
    std::size_t latency_frame_payload = 128;
    /// latency_hold: how long that ceiling stays after such traffic.
    Duration latency_hold = std::chrono::seconds(2);
    /// urgent_pacing: fraction of link_rate used while urgent traffic is active (either end), so the radios'
    /// buffers drain and an urgent message does not queue behind bytes already handed to the radio.
    double urgent_pacing = 0.93;

    /// priorities: levels 0 (highest: control) .. priorities-1 (bulk). Safe channel = priority.
    std::size_t priorities = 4;
    /// min_share: fraction of the link each priority gets when it has traffic, even under higher-priority
    /// load.
    std::array<double, kMaxPriorities> min_share{0.0, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05};

    /// safe_window: Safe segments in flight per channel (at most kMaxSafeWindow).
    std::size_t safe_window = 64;
    /// safe_queue_bytes: queued plus unacknowledged Safe bytes per channel; beyond it send_safe refuses.
    std::size_t safe_queue_bytes = 256 * 1024;
    /// max_message_size: largest message either class accepts (at most 255 x max_frame_payload).
    std::size_t max_message_size = 64 * 1024;
    /// retransmit_share: link share Safe retransmissions may take while Fast traffic waits.
    double retransmit_share = 0.3;
    /// ack_delay: longest wait before acknowledging Safe segments.
    Duration ack_delay = std::chrono::milliseconds(200);
    /// ack_every: acknowledge at once after this many new segments.
    std::size_t ack_every = 8;
    /// rto_initial: retransmission timeout before the first round-trip sample.
    Duration rto_initial = std::chrono::milliseconds(1000);
    /// rto_min, rto_max: bounds of the retransmission timeout; rto_max also caps the backoff.
    Duration rto_min = std::chrono::milliseconds(250);
    Duration rto_max = std::chrono::milliseconds(2000);

    /// fast_queue_cap: Fast messages waiting per priority; the oldest is dropped beyond it.
    std::size_t fast_queue_cap = 16;
    /// fast_reassembly_timeout: an incomplete fragmented Fast message is dropped after this.
    Duration fast_reassembly_timeout = std::chrono::milliseconds(1000);

    /// keepalive_interval: an idle path owes a probe frame after this much quiet; it goes with the next poll,
    /// or on its own timer after 1.5 x this.
    Duration keepalive_interval = std::chrono::milliseconds(500);
    /// probe_with_next_poll: whether an owed probe goes with the next transmit poll (it then shares the
    /// wake-up of whatever input comes, at the price of probing as soon as keepalive_interval has passed), or
    /// only on its own timer after 1.5 x keepalive_interval (fewer frames on an idle path: each one is a
    /// wake-up of the peer). The vehicle shares its wake-ups; the ground end spares the vehicle's.
    bool probe_with_next_poll = true;
    /// hello_interval: handshake retry period.
    Duration hello_interval = std::chrono::milliseconds(500);
    /// link_down_after: silence that marks a path (and with all paths, the link) down.
    Duration link_down_after = std::chrono::seconds(3);
    /// link_up_frames: valid frames needed to mark a path up again.
    std::size_t link_up_frames = 2;

    /// delivery_queue_cap: messages waiting for poll_message(); Safe segments are not acknowledged beyond it.
    std::size_t delivery_queue_cap = 1024;

    /// key: pre-shared 32-byte key (from key_file, read by the adapter). Without it frames carry no MAC and
    /// LinkStats::authenticated is false.
    std::optional<std::array<std::uint8_t, kKeyBytes>> key;
    /// second_key: a second pre-shared key a peer may use instead of `key` (needs `key`). Each session is
    /// bound to the key its handshake was authenticated with; session_key() says which, so an adapter can
    /// give the two keys different rights (airsegd: control and monitor).
    std::optional<std::array<std::uint8_t, kKeyBytes>> second_key;
    /// Random per process start, supplied by the adapter (the core never reads randomness). Must not be 0.
    std::uint64_t boot_nonce = 1;

    /// Every problem, each naming the field; empty when the configuration is usable.
    [[nodiscard]] std::vector<std::string> validate() const;
    /// Payload bytes per second the link carries: the slower of the serial port (link_rate) and the air net
    /// of each air packet's overhead. Budgets of the link's users are shares of this.
    [[nodiscard]] double carried_rate_bytes_per_s() const;
};

enum class SendResult : std::uint8_t {
    Accepted,
    Replaced,       ///< Fast: an unsent message of the same topic was replaced by this one
    DroppedOldest,  ///< Fast: accepted; the queue was full and its oldest message was dropped
    QueueFull,      ///< Safe: refused, the channel's queue is full; retry after messages are acknowledged
    TooLarge,       ///< refused: larger than max_message_size
    BadPriority,    ///< refused: priority >= TransportConfig::priorities
};
std::ostream& operator<<(std::ostream& os, SendResult r);

struct Delivered {
    MessageClass cls = MessageClass::Safe;
    std::uint8_t priority = 0;  ///< for Safe: the channel
    std::uint16_t topic = 0;    ///< Fast only (0 for Safe)
    std::vector<std::uint8_t> bytes;
};

struct TransportEvent {
    enum class Kind : std::uint8_t {
        SessionEstablished,  ///< a session with the peer is up (first time, or after either end restarted)
        PeerRestarted,       ///< the peer came back with a new boot nonce; stream state was reset
        LinkUp,
        LinkDown,
        PathUp,    ///< `path` hears valid frames again
        PathDown,  ///< `path` went silent
        /// the peer restarted while `count` Safe messages were in flight: they are sent again from the start
        /// in the new session (the old incarnation may have received some of them)
        SafeResent,
    };
    Kind kind = Kind::LinkUp;
    std::size_t path = 0;
    std::uint64_t count = 0;
};
std::ostream& operator<<(std::ostream& os, TransportEvent::Kind k);

/// Counters of one class in one direction (tx: what this end sent, rx: what it received).
struct ClassStats {
    std::uint64_t messages = 0;         ///< tx: accepted by send_*; rx: delivered
    std::uint64_t bytes = 0;            ///< message bytes (goodput numerator)
    std::uint64_t segments = 0;         ///< data chunks sent / received
    std::uint64_t retransmissions = 0;  ///< tx Safe: segments sent again
    std::uint64_t drops = 0;     ///< tx Fast: dropped by the cap; rx: duplicates, incomplete reassemblies
    std::uint64_t replaced = 0;  ///< tx Fast: replaced by a fresher value of the same topic
    std::uint64_t queue_depth =
        0;  ///< tx: messages waiting (snapshot); rx: messages waiting for poll_message
};

struct PathStats {
    std::uint64_t frames_sent = 0;
    std::uint64_t bytes_sent = 0;
    std::uint64_t frames_received = 0;  ///< valid frames
    std::uint64_t bytes_received = 0;   ///< every byte handed in
    bool alive = false;                 ///< this end hears valid frames on the path
    bool peer_hears = false;            ///< the peer's latest report says it hears this end on the path
};

struct LinkStats {
    bool authenticated = false;  ///< frames carry a MAC (a key is configured)
    bool session = false;
    bool link_up = false;
    double srtt_ms = 0.0;  ///< smoothed round-trip time (0 before the first sample)
    double rttvar_ms = 0.0;
    double rto_ms = 0.0;
    std::uint64_t rtt_samples = 0;
    std::size_t frame_payload = 0;  ///< current ceiling of chunk bytes per frame
    /// The goodput-optimal payload for the error rate this end's frames meet (0: no estimate yet).
    std::size_t peer_suggested_payload = 0;
    /// Byte error rate of the frames this end hears (its own measurement; -1 before enough frames).
    double byte_error_rate = -1.0;
    /// Byte error rate the peer reports for this end's frames (-1: no report yet); what frames are sized for.
    double peer_byte_error_rate = -1.0;
    bool fec = false;                       ///< this end sends its frames as shards with parity now
    std::size_t fec_shard_bytes = 0;        ///< data bytes per shard while fec
    std::uint64_t fec_frames_sent = 0;      ///< frames sent as shards
    std::uint64_t fec_frames_decoded = 0;   ///< frames rebuilt from received shards
    std::uint64_t fec_frames_repaired = 0;  ///< ... of which needed parity (a data shard was lost)
    std::uint64_t fec_shard_errors = 0;     ///< shards that failed their CRC-16
    double frame_loss = 0.0;                ///< fraction of sent Safe segments declared lost (moving average)
    /// The air as measured (docs/ground-link.md, "Measured air"): the payload rate to pace for, the payload
    /// rate delivered while this end was saturated (0 before it was), the turnaround beyond the frames' own
    /// time (-1 before a round trip), the least recent round trip, the seconds with an overflow; air_adapt:
    /// whether pacing follows air_carried.
    double air_carried = 0.0;
    double air_delivered = 0.0;
    double air_turnaround_ms = -1.0;
    double base_rtt_ms = 0.0;
    std::uint64_t air_overflows = 0;
    bool air_adapt = false;

    std::uint64_t frames_sent = 0;
    std::uint64_t frames_received = 0;  ///< valid, authenticated, not replayed
    std::uint64_t bytes_sent = 0;
    std::uint64_t bytes_received = 0;
    std::uint64_t framing_errors = 0;  ///< COBS errors, oversize or runt frames
    std::uint64_t crc_errors = 0;      ///< includes unkeyed frames of a stale session
    std::uint64_t mac_failures = 0;    ///< CRC fine, MAC wrong: forged, stale session or wrong key
    std::uint64_t replays = 0;    ///< authentic frames already seen or too old (redundant copies included)
    std::uint64_t malformed = 0;  ///< authentic frames whose content does not parse
    std::uint64_t oversized = 0;  ///< messages dropped for growing beyond max_message_size (Safe or Fast)
    std::uint64_t hellos_sent = 0;
    std::uint64_t hellos_received = 0;
    /// Frames whose authentication does not match this end's (each also counted above as a CRC or MAC
    /// failure): the peer has a key and this end none (its handshakes, or its frames before a session), this
    /// end a key and the peer's handshakes none, or handshakes under another key. What a ground end tells its
    /// operator instead of "no link".
    std::uint64_t frames_needing_key = 0;
    std::uint64_t hellos_without_key = 0;
    std::uint64_t hellos_with_other_key = 0;
    std::uint64_t peer_restarts = 0;
    std::uint64_t acks_sent = 0;  ///< ACK chunks
    std::uint64_t acks_received = 0;
    std::uint64_t safe_resent = 0;  ///< Safe messages sent again in a new session after a peer restart
    std::uint64_t events_dropped = 0;
    std::uint64_t deliveries_refused = 0;  ///< Safe segments not accepted because the delivery queue was full

    ClassStats tx_safe, tx_fast, rx_safe, rx_fast;
    std::array<PathStats, kMaxPaths> path{};
};

/// One end of the ground link.
///
/// Contract (sans-IO, after quinn-proto): the core never reads a clock, never touches a file descriptor, a
/// thread or randomness. Every call takes `now`, which must never go backwards.
///
///   inputs   send_safe / send_fast (application), handle_bytes(path, bytes) (raw bytes read from a port, any
///            chunking), handle_timeout(now)
///   outputs  poll_transmit(path) (one whole encoded frame, ready to write), poll_message(), poll_event(),
///            poll_timeout() (the single earliest deadline), stats()
///
/// Driver loop, after every input: for each path call poll_transmit(path, now) until it returns nullopt and
/// write each frame to that path's port at once; drain poll_message() and poll_event(); (re)arm one timer at
/// poll_timeout() and call handle_timeout(now) when it fires, then loop again. poll_transmit enforces the
/// pacing: it returns nothing until the path's byte-time budget (link_rate) allows the next frame, so the
/// bytes written to a path by time t never exceed link_rate × elapsed + one frame (with half_duplex, an end
/// using 45 % or more of the air also waits for the air budget it shares with the peer; docs/ground-link.md,
/// "Pacing"). poll_timeout() then includes the moment the budget frees up. Protocol errors never throw: they
/// are counted in stats().
class Transport {
  public:
    /// The configuration must be valid (see TransportConfig::validate); an invalid one throws
    /// std::invalid_argument listing the problems.
    Transport(TransportConfig config, TimePoint now);
    ~Transport();
    Transport(Transport&&) noexcept;
    Transport& operator=(Transport&&) noexcept;
    Transport(const Transport&) = delete;
    Transport& operator=(const Transport&) = delete;

    // ---- application side
    /// Queue a Safe message on channel `priority`. Messages of one channel arrive exactly once, in order.
    SendResult send_safe(std::uint8_t priority, std::span<const std::uint8_t> msg, TimePoint now);
    /// Queue a Fast message: replaces an unsent message of the same (priority, topic); the per-priority queue
    /// keeps at most fast_queue_cap messages and drops the oldest.
    SendResult send_fast(std::uint8_t priority, std::uint16_t topic, std::span<const std::uint8_t> msg,
                         TimePoint now);
    std::optional<Delivered> poll_message();
    std::optional<TransportEvent> poll_event();

    // ---- wire side
    void handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes, TimePoint now);
    /// The next frame (COBS-encoded, delimited) to write to `path` now, or nullopt when there is nothing to
    /// send or the pacing budget does not allow it yet.
    std::optional<std::vector<std::uint8_t>> poll_transmit(std::size_t path, TimePoint now);
    [[nodiscard]] TimePoint poll_timeout() const;
    void handle_timeout(TimePoint now);

    // ---- observation
    [[nodiscard]] const LinkStats& stats() const;
    [[nodiscard]] bool link_up() const;
    [[nodiscard]] bool session_established() const;
    /// Key of the current session: 0 for TransportConfig::key (or no key), 1 for second_key.
    [[nodiscard]] std::size_t session_key() const;
    [[nodiscard]] const TransportConfig& config() const;
    /// Safe messages of `priority` queued or in flight (not yet acknowledged).
    [[nodiscard]] std::size_t safe_pending(std::uint8_t priority) const;
    /// When `path`, left quiet, sends an empty probe on its own timer (its last frame + 1.5 ×
    /// keepalive_interval); kNever for a path that is not probed (or before the session). Any frame sent on
    /// the path before then makes that probe unneeded.
    [[nodiscard]] TimePoint probe_deadline(std::size_t path) const;
    /// Whether `path` owes a probe at `now` (keepalive_interval of quiet): the next transmit poll sends one
    /// unless something else goes first.
    [[nodiscard]] bool probe_owed(std::size_t path, TimePoint now) const;

    class Impl;

  private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace airseg::groundlink
