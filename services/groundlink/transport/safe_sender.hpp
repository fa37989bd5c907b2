#pragma once
// Sending half of one Safe channel: a bounded message queue cut lazily into segments (so each segment takes
// the frame size current when it is first sent), a window of segments in flight, selective acknowledgement,
// time-ordered loss detection (a segment is lost once a segment sent after it is acknowledged) and a
// retransmission timeout with exponential backoff.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "base/time.hpp"
#include "services/groundlink/transport/frame.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

class SafeSender {
  public:
    SafeSender(std::size_t window, std::size_t queue_bytes, std::size_t max_message)
        : window_(window), queue_bytes_(queue_bytes), max_message_(max_message) {}

    SendResult enqueue(std::span<const std::uint8_t> msg);

    struct Segment {
        std::uint16_t seq = 0;
        bool end = false;
        std::vector<std::uint8_t> data;
        bool retransmission = false;
    };

    [[nodiscard]] bool has_lost() const { return lost_count_ > 0; }
    [[nodiscard]] bool can_send_new() const { return !queue_.empty() && next_ - una_ < window_; }
    /// Size of the data of the lowest lost segment (it is resent as it was cut).
    [[nodiscard]] std::size_t lost_size() const;
    /// Resends the lowest lost segment; with `repeat_twice_lost`, a segment already lost twice is sent in two
    /// consecutive frames (the second once frame_done() says the first is complete).
    Segment take_lost(TimePoint now, bool repeat_twice_lost = false);
    /// Cuts the next segment with at most `max_data` bytes; nullopt when the window is closed, nothing is
    /// queued, or `max_data` is too small to keep the message within 255 fragments (`force`: then cut the
    /// smallest segment that does).
    std::optional<Segment> take_new(std::size_t max_data, bool force, TimePoint now);
    /// The frame being filled is complete: second copies of repeated segments become due for the next.
    void frame_done();

    struct AckResult {
        std::size_t newly_acked = 0;
        std::size_t newly_acked_bytes = 0;
        std::size_t newly_lost = 0;
        std::optional<Duration> rtt_sample;
        std::size_t rtt_sample_bytes = 0;  ///< data bytes of the segment the sample timed
        bool progress = false;             ///< the lowest unacknowledged segment advanced
    };
    /// `reorder_slack`: a segment counts as lost only if one sent more than this later was acknowledged
    /// (frames on two paths may arrive out of order).
    AckResult on_ack(const frame::AckChunk& ack, TimePoint now, Duration reorder_slack = Duration::zero());
    /// Declares the oldest outstanding segment lost if it was last sent at or before now - rto; returns how
    /// many (0 or 1). That segment becomes the probe: until an acknowledgement arrives, only it is timed (and
    /// resent, backed off, each time it times out). The rest of the window went out before it, so the
    /// acknowledgement its resending brings back judges them; timing each on its own would send the whole
    /// window again every timeout into a link that has gone quiet (RFC 6298, 5.4-5.6, does the same).
    std::size_t on_timeout(TimePoint now, Duration rto);
    /// When the oldest outstanding segment times out (kNever when none is outstanding).
    [[nodiscard]] TimePoint next_timeout(Duration rto) const;

    /// Starts over for a new session: every message not yet fully acknowledged goes back to the queue, in
    /// order, to be sent again from sequence 0. Returns how many had been started.
    std::size_t reset();

    [[nodiscard]] std::size_t pending_messages() const { return queue_.size() + started_.size(); }
    [[nodiscard]] std::size_t in_flight() const { return static_cast<std::size_t>(next_ - una_); }

  private:
    struct InFlight {
        std::vector<std::uint8_t> data;
        bool end = false;
        bool acked = false;
        bool lost = false;
        std::uint32_t transmissions = 0;
        bool repeat_due = false;   // a second copy goes in the next frame
        bool second_copy = false;  // marked lost for that second copy
        TimePoint last_sent{};
    };
    void mark_acked(InFlight& s, AckResult& r, TimePoint now, TimePoint& newest_acked_send);
    void pop_acked_front();

    std::size_t window_, queue_bytes_, max_message_;
    std::deque<std::vector<std::uint8_t>> queue_;    // front may be partly cut
    std::size_t cut_offset_ = 0;                     // bytes of queue_.front() already in segments
    std::size_t cut_fragments_ = 0;                  // segments cut from queue_.front()
    std::size_t bytes_held_ = 0;                     // queued + in flight
    std::deque<std::vector<std::uint8_t>> started_;  // fully cut, not yet fully acknowledged
    std::deque<InFlight> inflight_;                  // index = seq - una_
    std::uint64_t una_ = 0;
    std::uint64_t next_ = 0;
    std::size_t lost_count_ = 0;
    bool repeats_due_ = false;
    std::optional<std::uint64_t> probe_;  // sequence of the segment resent on the last timeout, until an ack
};

}  // namespace airseg::groundlink
