#pragma once
// Reference model of the MAREA Serial Transport Protocol as the source project describes it, weaknesses
// included, so the link benchmark can compare the ground-link transport against what flew before.
//
// Wire format (one frame):  DLE | body with every DLE doubled | DLE ETX
//   body of Safe/Fast:  type(1) seq(2, little-endian) frag_seq(1, 1-based) frag_total(1) data(<= 300)
//   CRC32(4, LE) body of ACK/NACK:   type(1) seq(2) frag_seq(1) frag_total(1) CRC32(4)  - echoes the header
//   of the fragment type: Fast 171, Safe 18, ACK 35, NACK 36. CRC32 is the IEEE/zlib CRC over the bytes
//   before it.
//
// Behaviour, as described:
//   - Safe fragments are remembered with the time they were written; one not acknowledged within
//     time_to_resend (1500 ms, fixed, no backoff, no round-trip estimate) is queued again. Every Safe message
//     is written at once: there is no window and no pacing, the sender writes as fast as the serial port
//     takes bytes.
//   - A receiver acknowledges every Safe fragment that passes its CRC (duplicates too). A frame failing its
//   CRC
//     whose first byte reads Safe is answered with a NACK carrying the sequence number read from the damaged
//     header; the sender resends that fragment at once.
//   - Messages larger than max_packet_size are cut into up to 255 fragments that share one sequence number.
//   - Fast messages wait in a queue of max_message_queue items; when it is full the oldest is discarded. They
//     are never resent; a Fast reassembly not completed within fast_reassembly_timeout is dropped.
//   - Transmit priority per frame: ACK/NACK, then Safe, then Fast.
//   - Completed messages are delivered in completion order (no ordering across messages).
// Where the text leaves a detail open (ACK contents per fragment, byte order, fragment numbering, how
// duplicates are recognised) the model picks the simplest reading that lets the protocol work;
// docs/simulators.md lists them.
//
// Contract (sans-IO): send_safe / send_fast / handle_bytes / handle_timeout in; poll_transmit (one whole
// frame, written by the driver at once), poll_message, poll_timeout out. Time is passed in and never goes
// backwards.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <vector>

#include "base/time.hpp"

namespace airseg::linkbench::seed {

inline constexpr std::uint8_t kDle = 0x10;
inline constexpr std::uint8_t kEtx = 0x03;

enum class FrameType : std::uint8_t { Fast = 171, Safe = 18, Ack = 35, Nack = 36 };

struct SeedConfig {
    Duration time_to_resend = std::chrono::milliseconds(1500);  ///< network.xml TimeToResend
    std::size_t max_packet_size = 300;                          ///< network.xml MaxPacketSize (fragment data)
    std::size_t max_message_queue = 20;                         ///< network.xml MaxMessageQueue (Fast)
    Duration fast_reassembly_timeout = std::chrono::seconds(3);
    std::size_t max_partial_safe = 256;  ///< incomplete Safe reassemblies kept (oldest dropped beyond)
    std::size_t max_raw_frame =
        4096;  ///< receive buffer bound before DLE ETX; beyond it the bytes are dropped
};

struct SeedStats {
    std::uint64_t frames_sent = 0;
    std::uint64_t bytes_sent = 0;
    std::uint64_t safe_fragments_sent = 0;
    std::uint64_t resent_on_timeout = 0;
    std::uint64_t resent_on_nack = 0;
    std::uint64_t acks_sent = 0;
    std::uint64_t nacks_sent = 0;
    std::uint64_t acks_received = 0;
    std::uint64_t nacks_received = 0;
    std::uint64_t crc_errors = 0;
    std::uint64_t raw_overflows = 0;
    std::uint64_t fast_dropped_queue = 0;
    std::uint64_t fast_dropped_incomplete = 0;
    std::uint64_t safe_duplicates = 0;
    std::uint64_t safe_partials_dropped = 0;
};

struct SeedMessage {
    bool safe = false;
    std::vector<std::uint8_t> bytes;
};

/// CRC-32 (IEEE 802.3, reflected, as zlib).
std::uint32_t crc32(std::span<const std::uint8_t> bytes);

/// Encodes one frame body (type..data) into the wire format (CRC, DLE doubling, delimiters).
std::vector<std::uint8_t> encode_frame(std::span<const std::uint8_t> body);

class SeedEndpoint {
  public:
    explicit SeedEndpoint(SeedConfig config = {});

    /// Refused (false) only when the message needs more than 255 fragments.
    bool send_safe(std::span<const std::uint8_t> msg, TimePoint now);
    bool send_fast(std::span<const std::uint8_t> msg, TimePoint now);

    void handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now);
    void handle_timeout(TimePoint now);
    std::optional<std::vector<std::uint8_t>> poll_transmit(TimePoint now);
    std::optional<SeedMessage> poll_message();
    TimePoint poll_timeout() const;

    /// Safe messages queued or written but not fully acknowledged.
    std::size_t safe_pending() const;
    const SeedStats& stats() const { return stats_; }

  private:
    struct FragmentKey {
        std::uint16_t seq;
        std::uint8_t frag;
        auto operator<=>(const FragmentKey&) const = default;
    };
    struct SentFragment {
        std::vector<std::uint8_t> frame;
        TimePoint sent_at{};
        bool queued = false;  // waiting in safe_queue_ for (re)transmission
    };
    struct Reassembly {
        std::uint8_t total = 0;
        std::map<std::uint8_t, std::vector<std::uint8_t>> parts;
        TimePoint started{};
    };

    std::vector<std::vector<std::uint8_t>> fragment(FrameType type, std::uint16_t seq,
                                                    std::span<const std::uint8_t> msg) const;
    void on_frame(std::span<const std::uint8_t> unescaped, TimePoint now);
    void on_data(FrameType type, FragmentKey key, std::uint8_t total, std::span<const std::uint8_t> data,
                 TimePoint now);
    void queue_control(FrameType type, FragmentKey key, std::uint8_t total);
    void requeue(FragmentKey key);

    SeedConfig config_;
    SeedStats stats_;
    std::uint16_t next_safe_seq_ = 0;
    std::uint16_t next_fast_seq_ = 0;

    std::deque<std::vector<std::uint8_t>> control_queue_;
    std::deque<FragmentKey> safe_queue_;
    std::map<FragmentKey, SentFragment> sent_;
    std::map<std::uint16_t, std::size_t> unacked_fragments_;         // per Safe seq
    std::deque<std::vector<std::vector<std::uint8_t>>> fast_queue_;  // messages, each as its frames
    std::deque<std::vector<std::uint8_t>> fast_in_progress_;

    std::vector<std::uint8_t> raw_;
    bool pending_dle_ = false;
    std::map<std::uint16_t, Reassembly> safe_rx_;
    std::map<std::uint16_t, Reassembly> fast_rx_;
    std::deque<std::uint16_t> completed_order_;
    std::set<std::uint16_t> completed_;
    std::deque<SeedMessage> delivered_;
};

}  // namespace airseg::linkbench::seed
