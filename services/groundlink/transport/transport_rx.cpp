// Frames in: deframing, CRC, authentication, replay window, handshake, chunk dispatch.
#include <algorithm>
#include <cmath>

#include "services/groundlink/transport/transport_impl.hpp"

namespace airseg::groundlink {
namespace {

constexpr std::int64_t kVanishedPerGap = 4;  // frames counted vanished for one gap in the numbering at most

}  // namespace

void Transport::Impl::handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes, TimePoint now) {
    current_time = std::max(current_time, now);
    if (path >= paths.size() || bytes.empty()) {
        return;
    }
    Path& ps = paths[path];
    stats.bytes_received += bytes.size();
    stats.path[path].bytes_received += bytes.size();
    // Only borrowing and the frame ceiling beside an urgent peer read it (an exp() a read).
    if ((cfg.path_mode == PathMode::Split && cfg.split_borrow) || cfg.half_duplex) {
        ps.rx_rate =
            decayed_rate(ps.rx_rate, ps.rx_rate_time, current_time) + static_cast<double>(bytes.size());
        ps.rx_rate_time = current_time;
    }
    if (cfg.half_duplex) {
        // The peer's bytes took air time of the shared pair: they count against the air budget of both ends,
        // with a margin (half as much again while the peer has urgent traffic) so that together the ends stay
        // below the air rate and a queue that built up in the radios drains. Only the heavier user waits for
        // that budget (air_ok), so a saturating end cannot starve the other.
        const Duration air = heard_air_time(bytes.size());
        ps.air_debt =
            std::max(ps.air_debt, current_time - air) + (peer_urgent ? air + air / 2 : air + air / 4);
        if (ps.own_air_debt > current_time) {
            ps.own_air_debt += air;  // this radio's queue waited while the peer's bytes had the air
        }
    }
    // Each frame heard also cost the radios a change of sender and back.
    const auto turnaround = [&] {
        if (cfg.half_duplex) {
            ps.air_debt = std::max(ps.air_debt, current_time) + 2 * cfg.air_turnaround;
        }
    };
    bool framed = false;  // a frame (or a damaged one) ended in these bytes
    ps.deframer.feed(
        bytes,
        [&](std::vector<std::uint8_t>&& plain) {
            framed = true;
            const std::size_t wire = ps.deframer.last_encoded_bytes();
            if (fec::is_shard(plain)) {
                // Shards come in bursts of one frame: one change of sender per group, not per shard.
                on_shard(path, plain, wire, current_time);
                return;
            }
            turnaround();
            on_plain_frame(path, plain, wire, current_time);
        },
        [&] {
            framed = true;
            turnaround();
            ++stats.framing_errors;
            ++ps.bad_since_shard;
            ++damaged_since_numbered;
            meter.on_frame(ps.deframer.last_encoded_bytes(), false);
        });
    if (!framed) {
        // Most serial reads are part of a frame: they move only the clock and the air budget.
        refresh_transmit(current_time);
        return;
    }
    update_link_state();
    refresh(current_time);
    update_plan();  // the error rate is measured only on frames heard
}

void Transport::Impl::on_shard(std::size_t path, std::span<const std::uint8_t> plain, std::size_t wire_bytes,
                               TimePoint now) {
    Path& ps = paths[path];
    const auto result = shards.add(plain, now, rebuilt);
    if (result == fec::ShardAssembler::Result::Bad) {
        ++stats.fec_shard_errors;
        ++ps.bad_since_shard;
        meter.on_frame(wire_bytes, false);
        return;
    }
    // Shards lost whole are as lost as damaged ones, and they are what tells lost air packets (runs of
    // missing shards) from byte errors to the meter.
    const auto id = fec::shard_id(plain);
    std::size_t gap = id.index;  // a group's first shard heard: those before it never arrived
    if (ps.last_shard && ps.last_shard->group == id.group) {
        gap = id.index > ps.last_shard->index ? id.index - ps.last_shard->index - 1U : 0U;
    }
    const std::size_t unheard = gap - std::min(gap, ps.bad_since_shard);
    for (std::size_t i = 0; i < unheard; ++i) {
        meter.on_frame(wire_bytes, false);
    }
    meter.on_vanished(static_cast<double>(unheard));
    ps.last_shard = id;
    ps.bad_since_shard = 0;
    meter.on_frame(wire_bytes, true);
    shards_heard_since_report = true;
    if (result == fec::ShardAssembler::Result::Complete) {
        stats.fec_frames_decoded = shards.groups_decoded();
        stats.fec_frames_repaired = shards.groups_repaired();
        if (cfg.half_duplex) {
            paths[path].air_debt = std::max(paths[path].air_debt, current_time) + 2 * cfg.air_turnaround;
        }
        const std::vector<std::uint8_t> frame = std::move(rebuilt);
        on_plain_frame(path, frame, 0, now);
    }
}

// A frame that fails its CRC one way and passes it the other (keyed CRCs carry no nonce prefix, unkeyed
// handshakes a zero one) came from a peer whose authentication differs from ours; a damaged frame passes
// neither.
void Transport::Impl::count_key_mismatch(std::span<const std::uint8_t> plain, bool keyed, frame::Kind kind) {
    const auto other = frame::check_crc(plain, !keyed, MacContext{});
    if (!other) {
        return;
    }
    if (!keyed && (kind == frame::Kind::Data || other->size() == 1 + frame::kHelloBodyBytes + kMacTagBytes)) {
        ++stats.frames_needing_key;
    } else if (keyed && kind == frame::Kind::Hello && other->size() == 1 + frame::kHelloBodyBytes) {
        ++stats.hellos_without_key;
    }
}

void Transport::Impl::on_plain_frame(std::size_t path, std::span<const std::uint8_t> plain,
                                     std::size_t wire_bytes, TimePoint now) {
    frame_wire_bytes = wire_bytes;
    const bool keyed = mac != nullptr;
    const auto kind = frame::kind_of(plain);
    const std::size_t tag_bytes = keyed ? kMacTagBytes : 0;
    if (!kind) {
        ++stats.crc_errors;
        ++damaged_since_numbered;
        meter.on_frame(wire_bytes, false);
        return;
    }
    MacContext ctx{};
    if (*kind == frame::Kind::Data) {
        ctx = MacContext{peer_nonce, my_nonce, 0};
    }
    const auto body = frame::check_crc(plain, keyed, ctx);
    if (!body || body->size() < tag_bytes + 1) {
        if (*kind == frame::Kind::Hello || (!keyed && !established)) {
            count_key_mismatch(plain, keyed, *kind);
        }
        ++stats.crc_errors;
        if (keyed || established || *kind == frame::Kind::Hello) {
            ++damaged_since_numbered;
            meter.on_frame(wire_bytes, false);
        }
        return;
    }
    meter.on_frame(wire_bytes, true);
    const auto frame_bytes = body->first(body->size() - tag_bytes);
    const auto tag = body->subspan(body->size() - tag_bytes);
    if (*kind == frame::Kind::Hello) {
        std::size_t key = 0;
        if (keyed) {
            while (key < keys.size() && !(keys[key] && keys[key]->verify(ctx, frame_bytes, tag))) {
                ++key;
            }
            if (key == keys.size()) {
                ++stats.mac_failures;
                ++stats.hellos_with_other_key;
                return;
            }
        }
        const auto hello = frame::decode_hello(frame_bytes);
        if (!hello) {
            ++stats.malformed;
            return;
        }
        on_hello(path, *hello, key, now);
        return;
    }
    if (!established) {
        ++stats.mac_failures;  // no session to authenticate it against
        return;
    }
    const auto truncated = frame::frame_number_of(frame_bytes);
    if (!truncated) {
        ++stats.malformed;
        return;
    }
    const std::uint64_t number = rx_window.reconstruct(*truncated);
    ctx.frame_number = number;
    if (keyed && !mac->verify(ctx, frame_bytes, tag)) {
        ++stats.mac_failures;
        return;
    }
    if (rx_window.check(number) != ReplayWindow::Check::Fresh) {
        ++stats.replays;
        return;
    }
    // A long silence skips many numbers at once; a few tell as much.
    // Damaged frames heard since the last numbered one account for part of a gap (their numbers could not
    // be read); the rest never arrived.
    const std::int64_t skipped = rx_window.skipped_by(number);
    const std::int64_t unheard =
        skipped < 0 ? -1
                    : std::max<std::int64_t>(0, skipped - static_cast<std::int64_t>(damaged_since_numbered));
    meter.on_vanished(static_cast<double>(std::min(unheard, kVanishedPerGap)));
    damaged_since_numbered = 0;
    rx_window.accept(number);
    on_authentic(path, frame::heard_mask_of(frame_bytes), now);
    peer_urgent = frame::urgent_of(frame_bytes);
    if (!confirmed) {
        confirmed = true;
    }
    on_data_frame(frame_bytes, now);
}

void Transport::Impl::on_authentic(std::size_t path, std::uint8_t peer_heard_mask, TimePoint now) {
    Path& ps = paths[path];
    if (!ps.alive) {
        if (ps.streak > 0 && now - ps.last_heard > cfg.link_down_after) {
            ps.streak = 0;
        }
        if (++ps.streak >= cfg.link_up_frames) {
            ps.alive = true;
            push_event(TransportEvent::Kind::PathUp, path);
        }
    }
    ps.last_heard = now;
    ++stats.frames_received;
    ++stats.path[path].frames_received;
    peer_mask = peer_heard_mask;
    peer_mask_time = now;
    peer_mask_known = true;
}

void Transport::Impl::on_data_frame(std::span<const std::uint8_t> frame_bytes, TimePoint now) {
    const auto chunks = frame::decode_chunks(frame_bytes);
    if (!chunks) {
        ++stats.malformed;
        return;
    }
    for (const auto& c : *chunks) {
        if (const auto* s = std::get_if<frame::SafeChunk>(&c)) {
            on_safe(*s, now);
        } else if (const auto* f = std::get_if<frame::FastChunk>(&c)) {
            on_fast(*f, now);
        } else if (const auto* a = std::get_if<frame::AckChunk>(&c)) {
            on_ack(*a, now);
        } else if (const auto* r = std::get_if<frame::ReportChunk>(&c)) {
            peer_error = static_cast<double>(r->byte_error_ppm & 0x7FFFU) * frame::kReportRateUnit;
            peer_bursty = (r->byte_error_ppm & frame::kReportBursty) != 0;
            update_plan();
        }
    }
}

void Transport::Impl::on_safe(const frame::SafeChunk& c, TimePoint now) {
    if (c.channel >= receivers.size()) {
        ++stats.malformed;
        return;
    }
    ++stats.rx_safe.segments;
    AckState& ack = acks[c.channel];
    if (deliveries.size() >= cfg.delivery_queue_cap) {
        ++stats.deliveries_refused;  // not acknowledged: the sender retries once the application catches up
        return;
    }
    SafeReceiver& rx = receivers[c.channel];
    const auto oversized_before = rx.oversize_dropped();
    const auto result = rx.on_segment(c);
    stats.oversized += rx.oversize_dropped() - oversized_before;
    if (!ack.needed) {
        ack.first = now;
    }
    ack.needed = true;
    switch (result) {
        case SafeReceiver::Accept::Fresh:
            air_estimate.on_heard(c.data.size());
            ++ack.unacked;
            if (rx.has_gap() || ack.unacked >= cfg.ack_every) {
                ack.immediate = true;
            }
            break;
        case SafeReceiver::Accept::Duplicate:
            ++stats.rx_safe.drops;
            ack.immediate = true;
            break;
        case SafeReceiver::Accept::OutOfWindow:
            ack.immediate = true;
            break;
    }
    while (auto m = rx.pop_message()) {
        ++stats.rx_safe.messages;
        stats.rx_safe.bytes += m->size();
        deliveries.push_back(Delivered{MessageClass::Safe, c.channel, 0, std::move(*m)});
        ++stats.rx_safe.queue_depth;
    }
}

void Transport::Impl::on_fast(const frame::FastChunk& c, TimePoint now) {
    if (c.priority >= fast.size()) {
        ++stats.malformed;
        return;
    }
    ++stats.rx_fast.segments;
    air_estimate.on_heard(c.data.size());
    std::optional<std::vector<std::uint8_t>> whole;
    if (!c.fragmented) {
        whole.emplace(c.data.begin(), c.data.end());
    } else {
        const auto before = reassembly.dropped();
        const auto oversized_before = reassembly.oversized();
        whole = reassembly.add(c, now);
        stats.rx_fast.drops += reassembly.dropped() - before;
        stats.oversized += reassembly.oversized() - oversized_before;
    }
    if (!whole) {
        return;
    }
    if (deliveries.size() >= cfg.delivery_queue_cap) {
        ++stats.rx_fast.drops;
        return;
    }
    ++stats.rx_fast.messages;
    stats.rx_fast.bytes += whole->size();
    deliveries.push_back(Delivered{MessageClass::Fast, c.priority, c.topic, std::move(*whole)});
    ++stats.rx_fast.queue_depth;
}

void Transport::Impl::on_ack(const frame::AckChunk& a, TimePoint now) {
    if (a.channel >= senders.size()) {
        ++stats.malformed;
        return;
    }
    ++stats.acks_received;
    const auto r = senders[a.channel].on_ack(a, now, reorder_slack());
    if (r.rtt_sample) {
        rtt.sample(*r.rtt_sample);
        measure_round_trip(*r.rtt_sample, r.rtt_sample_bytes, now);
    }
    air_estimate.on_acked(r.newly_acked_bytes, r.newly_acked);
    air_estimate.on_lost(r.newly_lost);
    if (r.progress) {
        backoff[a.channel] = 0;
    }
    lost_window += static_cast<double>(r.newly_lost);
}

// ---- handshake (docs/ground-link.md, "Sessions")

std::uint64_t Transport::Impl::fresh_nonce() {
    std::uint64_t v = 0;
    do {
        ++nonce_counter;
        v = cfg.boot_nonce + nonce_counter * 0x9E3779B97F4A7C15ULL;
    } while (v == 0);
    return v;
}

void Transport::Impl::queue_hello_reply(const frame::Hello& h, std::size_t key) {
    hello_reply = h;
    hello_reply_key = key;
    hello_reply_paths = static_cast<std::uint8_t>((1U << paths.size()) - 1U);
}

void Transport::Impl::on_hello(std::size_t path, const frame::Hello& h, std::size_t key, TimePoint now) {
    ++stats.hellos_received;
    if (established && h.sender_nonce == peer_nonce && h.echo_nonce == my_nonce) {
        if (key != session_key) {
            ++stats.mac_failures;  // the session's peer cannot hold the other key
            return;
        }
        on_authentic(path, h.heard_mask, now);
        if (h.established) {
            confirmed = true;
        } else {
            queue_hello_reply(frame::Hello{0, my_nonce, peer_nonce, true}, session_key);
        }
        return;
    }
    if (h.echo_nonce != 0 && h.echo_nonce == candidate) {
        // The sender echoed the nonce this end offered most recently: it is live, not a recording.
        accept_session(h.sender_nonce, key, now);
        on_authentic(path, h.heard_mask, now);
        if (h.established) {
            confirmed = true;
        }
        queue_hello_reply(frame::Hello{0, my_nonce, peer_nonce, true}, session_key);
        return;
    }
    if (!established || (h.sender_nonce != peer_nonce && (h.echo_nonce == 0 || h.echo_nonce == my_nonce))) {
        // A peer that is not the session's (it started, or it is a replay): challenge it with a fresh nonce;
        // the session changes only if the answer echoes it. A restarted peer may echo this end's session
        // nonce, learnt from the first hello it heard; ignoring it then would leave it unheard for good while
        // this end keeps talking to the incarnation that died. A hello echoing any other nonce is someone
        // else's challenge (or a recording of one): answering it would let a replay renegotiate a live
        // session.
        last_seen_peer = h.sender_nonce;
        unanswered_hellos = 0;
        queue_hello_reply(frame::Hello{0, candidate, h.sender_nonce, false}, key);
    }
}

void Transport::Impl::accept_session(std::uint64_t peer, std::size_t key, TimePoint now) {
    const bool had_session = established;
    session_key = key;
    if (keys[key]) {
        mac = keys[key].get();
    }
    established = true;
    confirmed = false;
    my_nonce = candidate;
    peer_nonce = peer;
    last_seen_peer = peer;
    candidate = fresh_nonce();
    rx_window.reset();
    next_frame_number = 0;
    std::size_t resent = 0;
    for (std::size_t l = 0; l < senders.size(); ++l) {
        resent += senders[l].reset();
        receivers[l].reset();
        acks[l] = AckState{};
        backoff[l] = 0;
    }
    reassembly.reset();
    for (Path& ps : paths) {
        ps.mirror.clear();
        ps.last_sent = now;
    }
    if (had_session) {
        ++stats.peer_restarts;
        push_event(TransportEvent::Kind::PeerRestarted);
        if (resent > 0) {
            stats.safe_resent += resent;
            push_event(TransportEvent::Kind::SafeResent, 0, resent);
        }
    }
    push_event(TransportEvent::Kind::SessionEstablished);
}

}  // namespace airseg::groundlink
