// Safe segments (fragmentation, selective acknowledgement, loss detection), Fast queue and reassembly,
// RTT/RTO.
#include <gtest/gtest.h>

#include "services/common/rtt_estimator.hpp"
#include "services/groundlink/transport/fast_queue.hpp"
#include "services/groundlink/transport/fast_reassembly.hpp"
#include "services/groundlink/transport/safe_receiver.hpp"
#include "services/groundlink/transport/safe_sender.hpp"

namespace airseg::groundlink {
namespace {

using std::chrono::milliseconds;
const TimePoint kStart = TimePoint{} + std::chrono::hours(1);

std::vector<std::uint8_t> seq_bytes(std::size_t n) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<std::uint8_t>(i * 13 + 1);
    }
    return v;
}

frame::SafeChunk chunk_of(const SafeSender::Segment& s) {
    return frame::SafeChunk{0, s.end, s.seq, s.data};
}

TEST(GroundlinkSafeSender, FragmentsLazilyAndReassemblesInOrder) {
    SafeSender tx(64, 1 << 20, 100000);
    SafeReceiver rx(64, 100000);
    const auto msg = seq_bytes(1000);
    ASSERT_EQ(tx.enqueue(msg), SendResult::Accepted);
    std::vector<SafeSender::Segment> segs;
    std::size_t size = 300;
    while (auto s = tx.take_new(size, false, kStart)) {
        segs.push_back(*s);
        size = 100;  // the frame size shrinks mid-message: later segments are cut smaller
    }
    ASSERT_EQ(segs.size(), 1U + 7U);
    EXPECT_EQ(segs[0].data.size(), 300U);
    EXPECT_TRUE(segs.back().end);
    for (auto it = segs.rbegin(); it != segs.rend(); ++it) {  // arrive in reverse order
        EXPECT_EQ(rx.on_segment(chunk_of(*it)), SafeReceiver::Accept::Fresh);
    }
    auto got = rx.pop_message();
    ASSERT_TRUE(got.has_value());
    EXPECT_EQ(*got, msg);
    EXPECT_EQ(rx.on_segment(chunk_of(segs[2])), SafeReceiver::Accept::Duplicate);
}

TEST(GroundlinkSafeSender, KeepsEveryMessageWithin255Fragments) {
    SafeSender tx(128, 1 << 20, 255 * 64);
    ASSERT_EQ(tx.enqueue(seq_bytes(255 * 64)), SendResult::Accepted);
    EXPECT_FALSE(tx.take_new(10, false, kStart).has_value());  // 10-byte pieces would need 1632 fragments
    auto forced = tx.take_new(10, true, kStart);
    ASSERT_TRUE(forced.has_value());
    EXPECT_EQ(forced->data.size(), 64U);
}

TEST(GroundlinkSafeSender, BoundedQueueRefusesWhenFullAndTooLarge) {
    SafeSender tx(4, 1000, 600);
    EXPECT_EQ(tx.enqueue(seq_bytes(601)), SendResult::TooLarge);
    EXPECT_EQ(tx.enqueue(seq_bytes(600)), SendResult::Accepted);
    EXPECT_EQ(tx.enqueue(seq_bytes(500)), SendResult::QueueFull);
    EXPECT_EQ(tx.enqueue(seq_bytes(400)), SendResult::Accepted);
}

TEST(GroundlinkSafeSender, SelectiveAckResendsOnlyTheHoleAndWindowBounds) {
    SafeSender tx(8, 1 << 20, 100000);
    for (int i = 0; i < 20; ++i) {
        ASSERT_EQ(tx.enqueue(seq_bytes(10)), SendResult::Accepted);
    }
    std::vector<SafeSender::Segment> segs;
    for (int i = 0; i < 8; ++i) {
        auto s = tx.take_new(100, false, kStart + milliseconds(i));
        ASSERT_TRUE(s.has_value());
        segs.push_back(*s);
    }
    EXPECT_FALSE(tx.can_send_new());  // window of 8 is full
    SafeReceiver rx(8, 100000);
    for (std::size_t i = 0; i < segs.size(); ++i) {
        if (i != 2) {
            rx.on_segment(chunk_of(segs[i]));
        }
    }
    EXPECT_TRUE(rx.has_gap());
    const auto ack = rx.make_ack(0);
    EXPECT_EQ(ack.next_expected, 2);
    const auto r = tx.on_ack(ack, kStart + milliseconds(200));
    EXPECT_EQ(r.newly_acked, 7U);
    EXPECT_EQ(r.newly_lost, 1U);  // segment 2: later segments were acknowledged
    ASSERT_TRUE(tx.has_lost());
    const auto again = tx.take_lost(kStart + milliseconds(201));
    EXPECT_EQ(again.seq, 2);
    EXPECT_TRUE(again.retransmission);
    EXPECT_FALSE(tx.has_lost());
    // The same ACK arriving again must not declare the resent segment lost a second time.
    EXPECT_EQ(tx.on_ack(ack, kStart + milliseconds(202)).newly_lost, 0U);
    rx.on_segment(chunk_of(again));
    tx.on_ack(rx.make_ack(0), kStart + milliseconds(400));
    EXPECT_EQ(tx.in_flight(), 0U);
    EXPECT_TRUE(tx.can_send_new());
}

TEST(GroundlinkSafeSender, TimeoutDeclaresOutstandingLostAndKarnSkipsRetransmittedSamples) {
    SafeSender tx(8, 1 << 20, 100000);
    tx.enqueue(seq_bytes(10));
    auto s = tx.take_new(100, false, kStart);
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(tx.next_timeout(milliseconds(500)), kStart + milliseconds(500));
    EXPECT_EQ(tx.on_timeout(kStart + milliseconds(499), milliseconds(500)), 0U);
    EXPECT_EQ(tx.on_timeout(kStart + milliseconds(500), milliseconds(500)), 1U);
    tx.take_lost(kStart + milliseconds(500));
    frame::AckChunk ack{0, 1, {}};
    const auto r = tx.on_ack(ack, kStart + milliseconds(600));
    EXPECT_EQ(r.newly_acked, 1U);
    EXPECT_FALSE(r.rtt_sample.has_value());
    EXPECT_TRUE(r.progress);
}

TEST(GroundlinkSafeSender, AfterATimeoutOnlyTheProbeIsTimedUntilAnAcknowledgementJudgesTheRest) {
    SafeSender tx(8, 1 << 20, 100000);
    tx.enqueue(seq_bytes(400));
    for (int i = 0; i < 4; ++i) {
        ASSERT_TRUE(tx.take_new(100, false, kStart + milliseconds(i)).has_value());
    }
    ASSERT_EQ(tx.on_timeout(kStart + milliseconds(500), milliseconds(500)), 1U);
    EXPECT_EQ(tx.take_lost(kStart + milliseconds(500)).seq, 0);
    // Segments 1..3 are older than the probe but are not timed on their own: a quiet link gets one segment
    // per timeout, not the whole window.
    EXPECT_EQ(tx.next_timeout(milliseconds(1000)), kStart + milliseconds(1500));
    EXPECT_EQ(tx.on_timeout(kStart + milliseconds(510), milliseconds(1000)), 0U);
    EXPECT_FALSE(tx.has_lost());
    ASSERT_EQ(tx.on_timeout(kStart + milliseconds(1500), milliseconds(1000)), 1U);  // the probe again
    EXPECT_EQ(tx.take_lost(kStart + milliseconds(1500)).seq, 0);
    // Its acknowledgement declares the segments sent before it lost, and timing returns to normal.
    const auto r = tx.on_ack(frame::AckChunk{0, 1, {}}, kStart + milliseconds(1600));
    EXPECT_EQ(r.newly_acked, 1U);
    EXPECT_EQ(r.newly_lost, 3U);
    for (std::uint16_t seq = 1; seq <= 3; ++seq) {
        EXPECT_EQ(tx.take_lost(kStart + milliseconds(1600 + seq)).seq, seq);
    }
    EXPECT_EQ(tx.next_timeout(milliseconds(500)), kStart + milliseconds(2101));
}

TEST(GroundlinkSafeSender, ResetRequeuesUnacknowledgedMessagesInOrder) {
    SafeSender tx(8, 1 << 20, 100000);
    tx.enqueue(seq_bytes(100));
    tx.enqueue(seq_bytes(100));
    tx.enqueue(seq_bytes(100));
    ASSERT_TRUE(tx.take_new(100, false, kStart).has_value());  // first message whole
    ASSERT_TRUE(tx.take_new(40, false, kStart).has_value());   // second message partly
    EXPECT_EQ(tx.reset(), 2U);
    EXPECT_EQ(tx.pending_messages(), 3U);
    for (int i = 0; i < 3; ++i) {
        auto s = tx.take_new(1000, false, kStart);
        ASSERT_TRUE(s.has_value());
        EXPECT_EQ(s->seq, i);
        EXPECT_EQ(s->data.size(), 100U);  // whole again, from the start
        EXPECT_TRUE(s->end);
    }
}

TEST(GroundlinkSafeReceiver, WindowBoundsHeldSegments) {
    SafeReceiver rx(4, 1000);
    const std::vector<std::uint8_t> d{1};
    EXPECT_EQ(rx.on_segment(frame::SafeChunk{0, true, 4, d}), SafeReceiver::Accept::OutOfWindow);
    EXPECT_EQ(rx.on_segment(frame::SafeChunk{0, true, 3, d}), SafeReceiver::Accept::Fresh);
    EXPECT_EQ(rx.on_segment(frame::SafeChunk{0, true, 0xFFFF, d}), SafeReceiver::Accept::Duplicate);
}

TEST(GroundlinkFastQueue, FreshestValueWinsAndCapDropsOldest) {
    FastQueue q(3);
    const std::vector<std::uint8_t> v1{1};
    const std::vector<std::uint8_t> v2{2};
    EXPECT_EQ(q.push(10, v1), SendResult::Accepted);
    EXPECT_EQ(q.push(11, v1), SendResult::Accepted);
    EXPECT_EQ(q.push(10, v2), SendResult::Replaced);
    EXPECT_EQ(q.size(), 2U);
    EXPECT_EQ(q.push(12, v1), SendResult::Accepted);
    EXPECT_EQ(q.push(13, v1), SendResult::DroppedOldest);  // topic 10 (oldest) goes
    std::vector<std::uint16_t> topics;
    while (auto p = q.take(100, false)) {
        topics.push_back(p->topic);
    }
    EXPECT_EQ(topics, (std::vector<std::uint16_t>{11, 12, 13}));
}

TEST(GroundlinkFastQueue, ReplacedValueKeepsItsPlace) {
    FastQueue q(8);
    const std::vector<std::uint8_t> old_v{1};
    const std::vector<std::uint8_t> new_v{9};
    q.push(1, old_v);
    q.push(2, old_v);
    q.push(1, new_v);
    auto first = q.take(100, false);
    ASSERT_TRUE(first.has_value());
    EXPECT_EQ(first->topic, 1);
    EXPECT_EQ(first->data, new_v);
}

TEST(GroundlinkFastQueue, FragmentsAndReassemblesAndTimesOut) {
    FastQueue q(4);
    const auto msg = seq_bytes(500);
    q.push(7, msg);
    std::vector<FastQueue::Piece> pieces;
    while (auto p = q.take(108, false)) {
        pieces.push_back(*p);
    }
    ASSERT_EQ(pieces.size(), 5U);
    EXPECT_TRUE(pieces.back().message_done);
    FastReassembly r(milliseconds(1000), 100000);
    std::optional<std::vector<std::uint8_t>> whole;
    for (std::size_t i = pieces.size(); i-- > 0;) {
        const auto& p = pieces[i];
        whole = r.add(frame::FastChunk{0, p.topic, true, p.msg_id, p.index, p.count, p.data}, kStart);
        if (i > 0) {
            EXPECT_FALSE(whole.has_value());
        }
    }
    ASSERT_TRUE(whole.has_value());
    EXPECT_EQ(*whole, msg);

    // A message missing a fragment is dropped after the timeout.
    const auto& p0 = pieces[0];
    r.add(frame::FastChunk{0, p0.topic, true, p0.msg_id, p0.index, p0.count, p0.data}, kStart);
    EXPECT_EQ(r.next_deadline(), kStart + milliseconds(1000));
    EXPECT_EQ(r.expire(kStart + milliseconds(999)), 0U);
    EXPECT_EQ(r.expire(kStart + milliseconds(1000)), 1U);
    EXPECT_EQ(r.next_deadline(), kNever);
}

TEST(GroundlinkFastQueue, LargeMessageStaysWithin255Fragments) {
    FastQueue q(4);
    q.push(1, seq_bytes(255 * 40));
    std::size_t n = 0;
    while (auto p = q.take(20, true)) {  // frames far too small: forced pieces keep the count at 255
        EXPECT_LE(p->count, 255);
        ++n;
    }
    EXPECT_EQ(n, 255U);
}

TEST(GroundlinkRttEstimator, AdaptsToSamplesAndBacksOffToTheCap) {
    RttEstimator r(milliseconds(1000), milliseconds(100), milliseconds(3000), milliseconds(20));
    EXPECT_EQ(r.rto(), milliseconds(1000));
    for (int i = 0; i < 50; ++i) {
        r.sample(milliseconds(200));
    }
    const double srtt_ms = std::chrono::duration<double, std::milli>(r.srtt()).count();
    EXPECT_NEAR(srtt_ms, 200.0, 1.0);
    const auto settled = r.rto();
    EXPECT_GE(settled, milliseconds(220));
    EXPECT_LE(settled, milliseconds(300));
    EXPECT_EQ(r.rto(1), settled * 2);
    EXPECT_EQ(r.rto(10), milliseconds(3000));
    for (int i = 0; i < 50; ++i) {
        r.sample(i % 2 == 0 ? milliseconds(100) : milliseconds(700));
    }
    EXPECT_GT(r.rto(), settled + milliseconds(300));  // variance widens the timeout
}

}  // namespace
}  // namespace airseg::groundlink

namespace airseg::groundlink {
namespace {

TEST(GroundlinkSafeSender, SegmentLostTwiceIsRepeatedOnALossyLink) {
    SafeSender tx(8, 1 << 20, 100000);
    tx.enqueue(seq_bytes(10));
    ASSERT_TRUE(tx.take_new(100, false, kStart).has_value());
    ASSERT_EQ(tx.on_timeout(kStart + milliseconds(500), milliseconds(500)), 1U);
    EXPECT_EQ(tx.take_lost(kStart + milliseconds(500), true).seq, 0);  // second transmission: once
    EXPECT_FALSE(tx.has_lost());
    ASSERT_EQ(tx.on_timeout(kStart + milliseconds(1000), milliseconds(500)), 1U);
    EXPECT_EQ(tx.take_lost(kStart + milliseconds(1000), true).seq, 0);  // third: twice in a row
    // Not twice in the same frame, which would share its fate: the second copy is due once it is complete.
    EXPECT_FALSE(tx.has_lost());
    tx.frame_done();
    ASSERT_TRUE(tx.has_lost());
    EXPECT_EQ(tx.take_lost(kStart + milliseconds(1010), true).seq, 0);
    tx.frame_done();
    EXPECT_FALSE(tx.has_lost());  // the second copy is not repeated again
}

TEST(GroundlinkSafeSender, ARepeatAcknowledgedBeforeItsFrameIsNotSent) {
    SafeSender tx(8, 1 << 20, 100000);
    tx.enqueue(seq_bytes(10));
    ASSERT_TRUE(tx.take_new(100, false, kStart).has_value());
    for (int i = 1; i <= 2; ++i) {
        ASSERT_EQ(tx.on_timeout(kStart + milliseconds(500 * i), milliseconds(500)), 1U);
        tx.take_lost(kStart + milliseconds(500 * i), true);
        tx.frame_done();
    }
    EXPECT_TRUE(tx.has_lost());  // the third transmission's second copy is due
    frame::AckChunk ack;
    ack.next_expected = 1;
    tx.on_ack(ack, kStart + milliseconds(1100));
    EXPECT_FALSE(tx.has_lost());
    tx.frame_done();
    EXPECT_FALSE(tx.has_lost());
}

}  // namespace
}  // namespace airseg::groundlink
