#pragma once
// Sans-IO MAVLink v1/v2 stream parser.
//
// Contract: the caller feeds bytes in any chunking with push(bytes, on_frame); on_frame(const Frame&) is
// called, synchronously and in stream order, for each frame found (the Frame reference is valid only during
// the call). finish(on_frame) tells the parser the stream has ended. The parser owns one fixed buffer of
// 2 * kMaxFrameLength bytes and never allocates after construction; it never reads a clock.
//
// What it accepts and how it recovers. The rule behind it: a verified frame (known id, matching checksum) is
// never given up for bytes that cannot be verified. A known id is one of ArduPilot's dialect
// (find_dialect_message, dialect.def); Frame::typed tells which of them messages.def declares.
//  - A frame with a known message id is delivered only when its checksum (with the message's CRC_EXTRA)
//    matches. A MAVLink 2 payload shorter than the message is zero-extended (payload_view() has the full
//    length); a longer one (fields of a newer definition) is delivered as received.
//  - MAVLink 2 frames with an incompatibility flag other than "signed" are dropped (incompat_rejected), as
//    the specification requires, once their checksum is verified; compatibility flags are ignored. A frame
//    with such a flag and an unknown message id can be neither verified nor delivered: its start byte is
//    given up at the header, as noise. Signed frames are delivered with is_signed set as soon as their
//    checksum is complete (signed_frames); the 13 bytes after it are taken as the signature, not verified,
//    unless a verified frame begins among them (a signature that lost a byte on the line).
//  - A message id without a known CRC_EXTRA cannot be verified. Such a frame is delivered with
//    checksum_verified == false (unknown_msgid) only when the byte right after it starts another frame (or
//    the stream ends there), and no verified frame begins inside it; otherwise its start byte is treated as
//    noise. So a stray 0xFD/0xFE in line noise, or a damaged length byte, does not swallow good frames: a
//    candidate with a known id and a plausible length (below) that starts inside an unknown frame is waited
//    for (until it can be judged, or until a verified frame after the unknown one is complete, whichever
//    comes first). Such an unknown frame may wait for later bytes; a verified frame after it is never held
//    back by that.
//  - After a bad checksum the parser rescans from the byte after the failed start byte, so a good frame that
//    begins inside a damaged or cut-short one is still found. It does not wait for a cut-short candidate to
//    fill up: as soon as a complete frame with a known id and a matching checksum lies inside a candidate,
//    the candidate is given up and that frame delivered (a lost byte would otherwise make the candidate
//    claim the wrong length and hold good frames back until unrelated later bytes arrive). A frame inside
//    another must also have a length its message can have (MAVLink 1: the base fields exactly; MAVLink 2:
//    at most all fields), since a checksum alone matches by chance once in 65,536 candidates. This is decided
//    as if the bytes came one at a time: the inner frame that is complete first wins, and only if it is
//    complete before the candidate itself could be judged; every start byte before it counts as a failed
//    candidate. Frames and counters therefore do not depend on how the stream is split into push() calls.
//    Each damaged stretch (from a failed start byte over the length it claims; a start byte inside an open
//    stretch does not extend it) is counted once: as `truncated` when a good frame began inside it (or the
//    stream ended inside it), else as `bad_checksum`. Other bytes not in a frame count as `garbage_bytes`.
//  - Sequence numbers are tracked per (sysid, compid); a gap of n counts n lost frames (seq_lost), the same
//    rule as the reference C library, so a repeated or reordered frame counts as a large gap.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>

#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/message_table.hpp"

namespace airseg::mavlink {

struct ParserStats {
    std::uint64_t frames_ok = 0;          // verified frames delivered
    std::uint64_t garbage_bytes = 0;      // bytes skipped outside any frame candidate
    std::uint64_t bad_checksum = 0;       // damaged frames (checksum mismatch)
    std::uint64_t truncated = 0;          // frames cut short by a new frame or by the end of the stream
    std::uint64_t unknown_msgid = 0;      // unverifiable frames delivered (no CRC_EXTRA for their id)
    std::uint64_t incompat_rejected = 0;  // MAVLink 2 frames with unknown incompatibility flags, dropped
    std::uint64_t signed_frames = 0;      // signed frames delivered (signature skipped)
    std::uint64_t seq_lost = 0;           // frames missing according to sequence gaps, all links
};

struct LinkStats {
    std::uint8_t sysid = 0;
    std::uint8_t compid = 0;
    std::uint8_t last_seq = 0;
    std::uint64_t received = 0;
    std::uint64_t lost = 0;
};

class Parser {
  public:
    /// Links whose sequence numbers are tracked at once; beyond that the least recently heard is forgotten.
    static constexpr std::size_t kMaxLinks = 32;

    template <class OnFrame>
    void push(std::span<const std::uint8_t> bytes, OnFrame&& on_frame) {
        push(bytes, Sink(on_frame));
    }
    template <class OnFrame>
    void finish(OnFrame&& on_frame) {
        finish(Sink(on_frame));
    }

    const ParserStats& stats() const { return stats_; }
    /// Sequence statistics of one sender, or nullptr if it has not been heard (or was forgotten).
    const LinkStats* link(std::uint8_t sysid, std::uint8_t compid) const;
    std::span<const LinkStats> links() const { return std::span(links_).first(link_count_); }

  private:
    // A non-owning reference to the caller's callable: the parsing code stays out of the header.
    class Sink {
      public:
        template <class F>
        explicit Sink(F& f)
            : object_(const_cast<void*>(static_cast<const void*>(&f))),
              call_([](void* o, const Frame& fr) { (*static_cast<std::remove_reference_t<F>*>(o))(fr); }) {}
        void operator()(const Frame& f) const { call_(object_, f); }

      private:
        void* object_;
        void (*call_)(void*, const Frame&);
    };
    enum class DamageKind : std::uint8_t { BadChecksum, Truncated };
    // What starts the buffer: noise before a start byte; the signature of the frame just delivered; a
    // candidate frame whose header is incomplete, whose id is known (verifiable), unknown, or unknown with an
    // unknown incompatibility flag (unacceptable).
    enum class Head : std::uint8_t { Noise, Signature, Incomplete, Known, Unknown, Unacceptable };

    void push(std::span<const std::uint8_t> bytes, Sink sink);
    void finish(Sink sink);
    Head head() const;
    std::size_t unverifiable_length(Head kind) const;
    std::size_t required_length() const;
    std::size_t pending_end(std::size_t first, std::size_t end, std::size_t at_least) const;
    // Out of line, so that a push that only appends costs little more than its bytes.
    [[gnu::noinline]] void push_and_judge(std::span<const std::uint8_t> bytes, Sink sink);
    std::size_t append_limit() const;
    void note_inner_starts(std::size_t first);
    bool resync_inside_candidate(Sink sink, std::size_t need);
    void account_failed_starts(std::size_t k);
    void step(Sink sink, bool at_end);
    void judge(Sink sink, Head kind);
    void accept(Sink sink, std::size_t frame_length, const MessageInfo* info);
    void deliver(Sink sink, std::size_t frame_length, const MessageInfo* info, std::size_t signature);
    void track_sequence(std::uint8_t sysid, std::uint8_t compid, std::uint8_t seq);
    void mark_damaged(std::size_t span, DamageKind kind);
    void discard(std::size_t n);
    void drop_front(std::size_t n);
    void resolve_damage_by_good_frame();

    // The head and what it needs to be judged: at most an unverifiable frame and a verified one starting in
    // its last byte.
    std::array<std::uint8_t, 2 * kMaxFrameLength> buf_{};
    std::size_t len_ = 0;
    // The start bytes inside the head that may still begin a verified frame (resync_inside_candidate), in
    // buffer order, each with the end of its checksum once its header is in (0 before). Kept as bytes
    // arrive, so that a push looks only at its own bytes, not again at the whole candidate.
    std::array<std::uint16_t, 2 * kMaxFrameLength> inner_at_{};
    std::array<std::uint16_t, 2 * kMaxFrameLength> inner_end_{};
    std::size_t inner_count_ = 0;
    std::size_t scanned_ = 0;       // bytes of the buffer looked at for start bytes
    std::size_t append_limit_ = 0;  // append_limit() after the last push
    // How many of the first bytes of the buffer (and of those still to come) are presumed the signature of
    // the frame just delivered.
    std::size_t signature_left_ = 0;
    mutable Head head_cache_ = Head::Noise;  // head(), once the candidate's header is complete
    mutable bool head_cached_ = false;
    mutable const MessageInfo* head_info_ = nullptr;  // a Known head's message
    mutable std::size_t head_checked_length_ = 0;     // a Known head's length up to its checksum
    std::size_t damaged_left_ = 0;
    DamageKind damage_kind_ = DamageKind::BadChecksum;
    Frame frame_{};
    std::size_t payload_dirty_ = 0;  // bytes of frame_.payload that may not be zero
    ParserStats stats_{};
    std::array<LinkStats, kMaxLinks> links_{};
    std::array<std::uint64_t, kMaxLinks> link_last_heard_{};
    std::size_t link_count_ = 0;
    std::uint64_t frames_seen_ = 0;
};

}  // namespace airseg::mavlink
