// Frames out: path selection, pacing, handshake frames and the scheduler that fills data frames.
#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "services/groundlink/transport/transport_impl.hpp"

namespace airseg::groundlink {
namespace {

constexpr std::size_t kMinUsefulSafe = 16;  // do not top up a frame with a Safe sliver smaller than this
constexpr std::size_t kMaxDataChunks = 64;
constexpr double kFairShare = 0.45;  // of the carried rate, below which an end is not held back on shared air
// Frame ceiling (in air time) while the peer is urgent and this end is not; longer while the peer sends
// only a trickle (under kPeerTrickle of the link: the vehicle's telemetry), whose few messages meet a frame
// on air rarely enough that bulk should not pay for them.
constexpr auto kPeerWaitAir = std::chrono::milliseconds(50);
constexpr auto kPeerTrickleWaitAir = std::chrono::milliseconds(100);
constexpr double kPeerTrickle = 0.1;
constexpr double kBulkFloor =
    0.2;  // of the carried rate, below which an end's bulk does not yield to the peer's
// Share of recent Safe segments declared lost above which frames stay at most kLossyFramePayload.
constexpr double kLossyFraction = 0.15;
constexpr std::size_t kLossyFramePayload = 192;
constexpr std::size_t kUnmeasuredFramePayload = 256;
// Safe segments sent before the share lost says anything.
constexpr double kLossJudgedAfter = 20.0;
// Share of recent Safe segments declared lost above which a segment lost twice is sent twice in a row.
constexpr double kRepeatFraction = 0.25;
constexpr unsigned kUnansweredHellosBeforeEchoingNothing = 3;

}  // namespace

bool Transport::Impl::peer_mask_fresh() const {
    return peer_mask_known && current_time - peer_mask_time < cfg.link_down_after;
}

std::uint8_t Transport::Impl::heard_mask() const {
    std::uint8_t m = 0;
    for (std::size_t p = 0; p < paths.size(); ++p) {
        if (paths[p].alive) {
            m = static_cast<std::uint8_t>(m | (1U << p));
        }
    }
    return m;
}

std::uint8_t Transport::Impl::header_flags() const {
    return static_cast<std::uint8_t>(heard_mask() | (current_time < urgent_until ? frame::kUrgentFlag : 0));
}

bool Transport::Impl::borrowed(std::size_t path) const {
    return cfg.path_mode == PathMode::Split && path != cfg.split_tx_path && carries_data(cfg.split_tx_path);
}

bool Transport::Impl::may_borrow(std::size_t path) const {
    const Path& ps = paths[path];
    // Not under heavy loss: the peer's acknowledgements on that pair matter more then.
    return cfg.split_borrow && ps.alive && !(peer_mask_fresh() && peer_urgent) && !lossy() &&
           decayed_rate(ps.rx_rate, ps.rx_rate_time, current_time) < 0.25 * carried_rate();
}

Duration Transport::Impl::reorder_slack() const {
    if (paths.size() < 2) {
        return Duration::zero();  // one serial path never reorders
    }
    return std::max<Duration>(rtt.srtt() / 4, frame_time(cfg.max_frame_payload + 32));
}

bool Transport::Impl::carries_data(std::size_t path) const {
    const auto bit = static_cast<std::uint8_t>(1U << path);
    switch (cfg.path_mode) {
        case PathMode::Single:
            return path == 0;
        case PathMode::Split: {
            const std::size_t primary = cfg.split_tx_path;
            const bool fallback = peer_mask_fresh() && ((peer_mask >> primary) & 1U) == 0;
            if (fallback) {
                return path != primary;
            }
            return path == primary || may_borrow(path);
        }
        case PathMode::Redundant:
            // A path the peer reports silent stops carrying data while another one works.
            return !peer_mask_fresh() || (peer_mask & bit) != 0 || (peer_mask & 0x03U & ~bit) == 0;
    }
    return false;
}

bool Transport::Impl::keeps_alive(std::size_t path) const {
    switch (cfg.path_mode) {
        case PathMode::Single:
            return path == 0;
        case PathMode::Split:
            return path == cfg.split_tx_path || carries_data(path);
        case PathMode::Redundant:
            return true;
    }
    return false;
}

bool Transport::Impl::lossy() const {
    return sent_window >= kLossJudgedAfter && lost_window > kLossyFraction * sent_window;
}

std::size_t Transport::Impl::payload_cap() const {
    std::size_t cap = cfg.max_frame_payload;
    if (cfg.adaptive_frame_size) {
        // Until the error rate is known, and until enough Safe segments went out to tell whether whole
        // frames are lost (which the error rate does not see), frames stay short: a Safe segment keeps the
        // length it was cut at when it is sent again, and a long one cut blind may never get through a bad
        // link (a kilobyte spans five air packets: at 30 % packet loss one try in six arrives).
        cap = plan_rate ? std::clamp(plan.payload, cfg.min_frame_payload, cfg.max_frame_payload)
                        : std::min(cap, kUnmeasuredFramePayload);
        if (sent_window < kLossJudgedAfter) {
            cap = std::min(cap, kUnmeasuredFramePayload);
        }
    }
    // Under heavy frame loss small frames shorten each repair round trip, which bounds stalls (shards with
    // parity already make each frame likely to arrive).
    // Whole frames lost (not bytes): the error rate says little about them, so this size holds.
    if (lossy() && !plan.fec) {
        cap = kLossyFramePayload;
    }
    // Under urgent traffic they bound how long a frame already on its way holds the urgent message back. The
    // peer's urgent traffic waits for this end's frames on shared air too, but only for the frame on air, and
    // a peer's telemetry trickle keeps it urgent all the time: there frames stay within kPeerWaitAir of air,
    // which costs bulk far less than the tightest ceiling.
    const bool peer_waiting = cfg.half_duplex && peer_urgent && peer_mask_fresh();
    if (current_time < urgent_until) {
        cap = std::min(cap, cfg.latency_frame_payload);
    } else if (peer_waiting) {
        double heard = 0.0;
        for (const Path& ps : paths) {
            heard += decayed_rate(ps.rx_rate, ps.rx_rate_time, current_time);
        }
        const auto wait = heard < kPeerTrickle * carried_rate() ? kPeerTrickleWaitAir : kPeerWaitAir;
        const auto peer_wait_bytes =
            static_cast<std::size_t>(carried_rate() * std::chrono::duration<double>(wait).count());
        cap = std::min(cap, std::max(cfg.latency_frame_payload, peer_wait_bytes));
    }
    return std::max(cap, cfg.min_frame_payload);
}

Transport::Impl::AirGate Transport::Impl::air_gate(std::size_t path) const {
    const Path& ps = paths[path];
    if (!cfg.half_duplex || current_time >= ps.air_debt) {
        return AirGate::Open;
    }
    if (radio_full(path)) {
        return AirGate::Closed;  // more would only wait in the radio, or overflow it
    }
    // An end using less than its fair share of the air (a little under half) is not held back, so a
    // saturating peer cannot starve it and two saturating ends share the air. A heavier end waits for the
    // air budget both ends share.
    const double rate = air_use(path);
    if (rate >= kFairShare * carried_rate()) {
        return AirGate::Closed;
    }
    // While the peer has urgent traffic and this end has none, only this end's urgent traffic goes, so the
    // peer's is not held back by bulk. Not when this end is urgent too (two ends with Fast traffic would
    // each wait for the other, and one direction would fall silent), nor below a floor of the air, so a
    // peer that is urgent all the time cannot silence this direction's bulk.
    const bool yield = peer_urgent && peer_mask_fresh() && current_time >= urgent_until &&
                       rate >= kBulkFloor * carried_rate();
    return yield ? AirGate::UrgentOnly : AirGate::Open;
}

double Transport::Impl::air_use(std::size_t path) const {
    const Path& ps = paths[path];
    // The average decays between frames; half a frame restores its mean over the sawtooth.
    return decayed_rate(ps.tx_rate, ps.tx_rate_time, current_time) + 0.5 * static_cast<double>(ps.last_frame);
}

bool Transport::Impl::radio_full(std::size_t path) const {
    if (cfg.radio_buffer_bytes == 0) {
        return false;
    }
    // Only this end's own bytes wait in its radio: a peer that talks much fills the air, not this radio
    // (counting the shared budget here closed the lighter end for as long as the heavier one talked).
    const double owed =
        std::chrono::duration<double>(paths[path].own_air_debt - current_time).count() * air_rate();
    return owed > 0.5 * static_cast<double>(cfg.radio_buffer_bytes);
}

TimePoint Transport::Impl::air_reopens(std::size_t path) const {
    const Path& ps = paths[path];
    if (cfg.radio_buffer_bytes == 0 || !radio_full(path)) {
        return ps.air_debt;
    }
    // The buffer alone holds it back: open once half the buffer is what remains owed.
    const auto room = std::chrono::duration_cast<Duration>(
        std::chrono::duration<double>(0.5 * static_cast<double>(cfg.radio_buffer_bytes) / air_rate()));
    const double rate = air_use(path);
    return rate >= kFairShare * carried_rate() ? std::max(ps.air_debt, ps.own_air_debt - room)
                                               : std::max(current_time, ps.own_air_debt - room);
}

Duration Transport::Impl::frame_time_at(std::size_t bytes, double rate, double scale) const {
    const double serial = static_cast<double>(bytes) / cfg.link_rate_bytes_per_s;
    double on_air = static_cast<double>(bytes);
    if (cfg.air_packet_payload != 0) {
        const std::size_t packets = (bytes + cfg.air_packet_payload - 1) / cfg.air_packet_payload;
        on_air += static_cast<double>(packets * cfg.air_packet_overhead);
    }
    const double air = on_air / rate;
    return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(std::max(serial, air) / scale));
}

Duration Transport::Impl::heard_air_time(std::size_t bytes) const {
    double on_air = static_cast<double>(bytes);
    if (cfg.air_packet_payload != 0) {
        on_air *= static_cast<double>(cfg.air_packet_payload + cfg.air_packet_overhead) /
                  static_cast<double>(cfg.air_packet_payload);
    }
    return std::chrono::duration_cast<Duration>(std::chrono::duration<double>(
        std::max(on_air / air_rate(), static_cast<double>(bytes) / cfg.link_rate_bytes_per_s)));
}

TimePoint Transport::Impl::ack_due() const {
    TimePoint t = kNever;
    for (const AckState& a : acks) {
        if (a.needed) {
            t = std::min(t, a.immediate ? current_time : a.first + cfg.ack_delay);
        }
    }
    return t;
}

TimePoint Transport::Impl::content_due(std::size_t path) const {
    const Path& ps = paths[path];
    TimePoint t = kNever;
    if (hello_reply && ((hello_reply_paths >> path) & 1U) != 0) {
        t = std::min(t, ps.last_hello + cfg.hello_interval / 4);
    }
    if (!confirmed) {
        return std::min(t, ps.next_hello);
    }
    if (carries_data(path)) {
        // The air gate (a decaying rate: an exp()) is judged only when there is data it could hold back.
        if (borrowed(path)) {
            // A borrowed path carries bulk only: urgent traffic keeps to this end's own pair.
            if (level_ready(senders.size() - 1, true)) {
                t = std::min(t, air_gate(path) == AirGate::Open ? current_time : air_reopens(path));
            }
        } else if (!ps.mirror.empty()) {
            return std::min(t, current_time);
        } else if (data_ready(true)) {
            const AirGate gate = air_gate(path);
            if (gate == AirGate::Open || (gate == AirGate::UrgentOnly && data_ready(false))) {
                return std::min(t, current_time);
            }
            t = std::min(t, air_reopens(path));
        }
        t = std::min(t, ack_due());
    }
    if (keeps_alive(path)) {
        // probe_deadline(), written out: this runs at every poll.
        t = std::min(t, ps.last_sent + cfg.keepalive_interval + cfg.keepalive_interval / 2);
    }
    return t;
}

// Half an interval of slack: a probe is owed after keepalive_interval of quiet and goes with any poll after
// that (with probe_with_next_poll), but wakes the process for itself only when the quiet has lasted 1.5
// intervals. A path carrying periodic data is never probed then, even when that data comes a little late to
// share a wake-up (the vehicle's 2 Hz telemetry, the same period as the probes).
TimePoint Transport::Impl::probe_deadline(std::size_t path) const {
    if (path >= paths.size() || !confirmed || !keeps_alive(path)) {
        return kNever;
    }
    return paths[path].last_sent + cfg.keepalive_interval + cfg.keepalive_interval / 2;
}

bool Transport::Impl::probe_owed(std::size_t path, TimePoint now) const {
    const Duration quiet =
        cfg.keepalive_interval + (cfg.probe_with_next_poll ? Duration::zero() : cfg.keepalive_interval / 2);
    return keeps_alive(path) && now >= paths[path].last_sent + quiet;
}

std::optional<std::vector<std::uint8_t>> Transport::Impl::poll_transmit(std::size_t path, TimePoint now) {
    current_time = std::max(current_time, now);
    if (path >= paths.size() || current_time < paths[path].next_free) {
        return std::nullopt;
    }
    // The transmit deadline refresh() computed at this very time still holds (every input refreshes): no
    // path has anything to send before it, so no frame needs building. The driver polls after every serial
    // read, most of which complete no frame.
    if (refreshed_at == current_time && current_time < timers[static_cast<std::size_t>(Timer::Transmit)]) {
        return std::nullopt;
    }
    auto out = build_hello(path, current_time);
    if (!out && confirmed) {
        out = build_data(path, current_time);
    }
    if (out) {
        account_sent(path, out->size(), current_time);
    }
    update_link_state();
    refresh(current_time);
    return out;
}

void Transport::Impl::account_sent(std::size_t path, std::size_t bytes, TimePoint now) {
    Path& ps = paths[path];
    const bool urgent = now < urgent_until;
    const Duration air = frame_time(bytes, urgent ? cfg.urgent_pacing : 1.0);
    ps.next_free = std::max(ps.next_free, now) + air;
    ps.air_debt = std::max(ps.air_debt, now) + air;  // the shared-air budget counts both ends
    ps.own_air_debt = std::max(ps.own_air_debt, now) + air;
    ps.tx_rate = decayed_rate(ps.tx_rate, ps.tx_rate_time, now) + static_cast<double>(bytes);
    ps.tx_rate_time = now;
    ps.last_frame = bytes;
    air_estimate.on_sent(bytes, data_ready(true));

    ps.last_sent = now;
    ++stats.frames_sent;
    stats.bytes_sent += bytes;
    ++stats.path[path].frames_sent;
    stats.path[path].bytes_sent += bytes;
}

std::optional<std::vector<std::uint8_t>> Transport::Impl::build_hello(std::size_t path, TimePoint now) {
    Path& ps = paths[path];
    const auto bit = static_cast<std::uint8_t>(1U << path);
    frame::Hello h;
    std::size_t hello_key = 0;
    if (hello_reply && (hello_reply_paths & bit) != 0 && now >= ps.last_hello + cfg.hello_interval / 4) {
        h = *hello_reply;
        hello_key = hello_reply_key;
        hello_reply_paths = static_cast<std::uint8_t>(hello_reply_paths & ~bit);
        if (hello_reply_paths == 0) {
            hello_reply.reset();
        }
    } else if (!confirmed && now >= ps.next_hello) {
        if (!established && last_seen_peer != 0 &&
            ++unanswered_hellos > kUnansweredHellosBeforeEchoingNothing) {
            last_seen_peer = 0;
        }
        h = established ? frame::Hello{0, my_nonce, peer_nonce, true}
                        : frame::Hello{0, candidate, last_seen_peer, false};
        hello_key = session_key;
        if (!established && keys[1]) {
            hello_key = unestablished_hellos++ % 2;  // the peer may hold either key
        }
    } else {
        return std::nullopt;
    }
    h.heard_mask = heard_mask();
    ps.next_hello = now + cfg.hello_interval;
    ps.last_hello = now;
    ++stats.hellos_sent;
    return to_wire(frame::encode_hello(h), keys[hello_key].get(), MacContext{});
}

bool Transport::Impl::add_data_chunk(std::vector<frame::Chunk>& chunks,
                                     std::vector<std::vector<std::uint8_t>>& storage, std::size_t& room,
                                     bool first, TimePoint now) {
    const std::size_t levels = senders.size();
    bool any_fast = false;  // Fast traffic this frame could carry
    for (std::size_t l = 0; l < levels; ++l) {
        any_fast = any_fast || (!fast[l].empty() && !(bulk_blocked && l + 1 == levels));
    }
    const bool retx_ok = retx_credit > 0.0 || !any_fast;

    // Level order: a lower level that has earned its minimum share goes first, then strict priority.
    std::array<std::size_t, 2 * kMaxPriorities> order{};
    std::size_t order_size = 0;
    for (std::size_t l = 1; l < levels; ++l) {
        if (share_credit[l] > 0.0 && level_ready(l, retx_ok)) {
            order[order_size++] = l;
        }
    }
    for (std::size_t l = 0; l < levels; ++l) {
        order[order_size++] = l;
    }

    for (const std::size_t l : std::span(order).first(order_size)) {
        if (!level_ready(l, retx_ok)) {
            continue;
        }
        SafeSender& tx = senders[l];
        const auto level = static_cast<std::uint8_t>(l);
        std::size_t used = 0;
        if (retx_ok && tx.has_lost() && (first || tx.lost_size() + frame::safe_chunk_overhead() <= room)) {
            auto seg = tx.take_lost(now, lost_window > kRepeatFraction * sent_window);
            storage.push_back(std::move(seg.data));
            chunks.emplace_back(frame::SafeChunk{level, seg.end, seg.seq, storage.back()});
            used = frame::safe_chunk_overhead() + storage.back().size();
            ++stats.tx_safe.retransmissions;
            retx_credit -= static_cast<double>(used);
        } else {
            const bool fast_first = fast_turn[l] || !tx.can_send_new();
            for (int attempt = 0; attempt < 2 && used == 0; ++attempt) {
                const bool try_fast = (attempt == 0) == fast_first;
                if (try_fast && !fast[l].empty()) {
                    if (auto piece = fast[l].take(room, first)) {
                        storage.push_back(std::move(piece->data));
                        chunks.emplace_back(frame::FastChunk{level, piece->topic, piece->fragmented,
                                                             piece->msg_id, piece->index, piece->count,
                                                             storage.back()});
                        used = frame::fast_chunk_overhead(piece->fragmented) + storage.back().size();
                        ++stats.tx_fast.segments;
                        fast_turn[l] = false;
                        mark_urgent(now);
                    }
                } else if (!try_fast && tx.can_send_new()) {
                    const std::size_t fit =
                        room > frame::safe_chunk_overhead() ? room - frame::safe_chunk_overhead() : 0;
                    if (!first && fit < kMinUsefulSafe) {
                        continue;
                    }
                    if (auto seg = tx.take_new(fit, first, now)) {
                        storage.push_back(std::move(seg->data));
                        chunks.emplace_back(frame::SafeChunk{level, seg->end, seg->seq, storage.back()});
                        used = frame::safe_chunk_overhead() + storage.back().size();
                        fast_turn[l] = true;
                        if (l + 1 < levels) {
                            mark_urgent(now);
                        }
                    }
                }
            }
            if (used == 0) {
                continue;
            }
        }
        if (std::holds_alternative<frame::SafeChunk>(chunks.back())) {
            ++stats.tx_safe.segments;
            sent_window += 1.0;
            if (sent_window > 400.0) {  // loss estimate over roughly the last few hundred segments
                sent_window /= 2;
                lost_window /= 2;
            }
        }
        share_credit[l] = std::max(share_credit[l] - static_cast<double>(used),
                                   -4.0 * static_cast<double>(cfg.max_frame_payload));
        room = room > used ? room - used : 0;
        return true;
    }
    return false;
}

std::optional<std::vector<std::uint8_t>> Transport::Impl::build_data(std::size_t path, TimePoint now) {
    Path& ps = paths[path];
    if (!ps.mirror.empty()) {
        auto f = std::move(ps.mirror.front());
        ps.mirror.pop_front();
        return f;
    }
    const bool keepalive_due = probe_owed(path, now);
    if (!carries_data(path)) {
        if (!keepalive_due) {
            return std::nullopt;
        }
        // A probe: an empty frame, so the peer can report whether it hears this path.
        auto plain = frame::encode_data(header_flags(), static_cast<std::uint32_t>(next_frame_number), {});
        const MacContext ctx{my_nonce, peer_nonce, next_frame_number++};
        return to_wire(std::move(plain), mac, ctx);
    }

    // Scratch kept from frame to frame (filling one allocates no vectors). Chunk spans point into the
    // storage's buffers, which stay where they are when the storage grows.
    auto& chunks = tx_chunks;
    auto& storage = tx_storage;
    auto& acked_channels = tx_acked;
    chunks.clear();
    storage.clear();
    acked_channels.clear();
    std::size_t room = payload_cap();
    const bool ack_is_due = ack_due() <= now;

    for (std::size_t l = 0; l < acks.size(); ++l) {
        if (acks[l].needed) {
            chunks.emplace_back(receivers[l].make_ack(static_cast<std::uint8_t>(l)));
            acked_channels.push_back(l);
        }
    }
    std::optional<std::uint32_t> report;  // committed only when the frame goes out
    if (const auto rate = meter.byte_error_rate()) {
        const auto ppm =
            static_cast<std::uint32_t>(std::min(std::round(*rate / frame::kReportRateUnit), 32767.0)) |
            (meter.bursty() ? frame::kReportBursty : 0U);
        const bool changed = !last_reported_ppm ||
                             std::abs(static_cast<double>(ppm) - static_cast<double>(*last_reported_ppm)) >
                                 std::max(0.1 * static_cast<double>(*last_reported_ppm), 1.0);
        // A clean link needs no report (the peer assumes the link symmetric and measures it clean too),
        // unless an error rate was reported before or the peer protects its frames with shards anyway.
        const bool worth_it = ppm != 0 || last_reported_ppm.value_or(0) != 0 || shards_heard_since_report;
        if (worth_it && (changed || now - last_report_time >= std::chrono::seconds(5))) {
            chunks.emplace_back(frame::ReportChunk{static_cast<std::uint16_t>(ppm)});
            report = ppm;
        }
    }
    for (const auto& c : chunks) {
        room = room > frame::encoded_size(c) ? room - frame::encoded_size(c) : 0;
    }
    std::size_t data_chunks = 0;
    const AirGate gate = air_gate(path);  // closed: only acknowledgements and keepalives go out
    bulk_blocked = gate == AirGate::UrgentOnly;
    bulk_only = borrowed(path);
    while (gate != AirGate::Closed && data_chunks < kMaxDataChunks &&
           add_data_chunk(chunks, storage, room, data_chunks == 0, now)) {
        ++data_chunks;
        if (room <= frame::safe_chunk_overhead()) {
            break;
        }
    }

    bulk_blocked = false;
    bulk_only = false;
    for (auto& tx : senders) {
        tx.frame_done();
    }
    if (data_chunks == 0 && !ack_is_due && !keepalive_due) {
        return std::nullopt;  // only opportunistic content: wait for a frame worth sending
    }
    if (report) {
        last_reported_ppm = report;
        last_report_time = now;
        shards_heard_since_report = false;
    }
    for (const std::size_t l : acked_channels) {
        acks[l] = AckState{};
        ++stats.acks_sent;
    }

    std::size_t payload = 0;
    for (const auto& c : chunks) {
        payload += frame::encoded_size(c);
    }
    // Credits for the scheduler: every ready level earns its minimum share, retransmissions their share.
    const auto frame_bytes = static_cast<double>(payload + frame::frame_overhead(mac != nullptr));
    const auto cap = static_cast<double>(cfg.max_frame_payload);
    for (std::size_t l = 1; l < senders.size(); ++l) {
        if (level_ready(l, true)) {
            share_credit[l] = std::min(share_credit[l] + cfg.min_share[l] * frame_bytes, cap);
        } else {
            share_credit[l] = std::min(share_credit[l], 0.0);
        }
    }
    retx_credit = std::min(retx_credit + cfg.retransmit_share * frame_bytes, cap);

    auto plain = frame::encode_data(
        header_flags(), static_cast<std::uint32_t>(next_frame_number & frame::kFrameNumberMask), chunks);
    const MacContext ctx{my_nonce, peer_nonce, next_frame_number++};
    auto sealed = to_wire(std::move(plain), mac, ctx);
    for (std::size_t q = 0; q < paths.size(); ++q) {
        if (q != path && cfg.path_mode == PathMode::Redundant && carries_data(q)) {
            if (paths[q].mirror.size() >= kMirrorCap) {
                paths[q].mirror.pop_front();
            }
            paths[q].mirror.push_back(sealed);
        }
    }
    return sealed;
}

}  // namespace airseg::groundlink

namespace airseg::groundlink {

std::optional<double> Transport::Impl::tx_error_rate() const {
    if (peer_error) {
        return peer_error;
    }
    return meter.byte_error_rate();
}

void Transport::Impl::update_plan() {
    if (!cfg.adaptive_frame_size) {
        return;
    }
    const auto rate = tx_error_rate();
    if (!rate) {
        return;
    }
    // Replanning costs binomial sums: only when the rate moved by a tenth or crossed zero.
    const bool bursty = peer_error ? peer_bursty : meter.bursty();
    if (plan_rate && (*rate == 0.0) == (*plan_rate == 0.0) &&
        std::abs(*rate - *plan_rate) <= 0.1 * *plan_rate && bursty == plan_bursty) {
        return;
    }
    plan_rate = rate;
    plan_bursty = bursty;
    // On half-duplex radios every frame also costs two changes of sender (acknowledgements come back in
    // between); a group of shards pays them once.
    const double turnaround_bytes =
        cfg.half_duplex ? 2.0 * std::chrono::duration<double>(cfg.air_turnaround).count() * carried_rate()
                        : 0.0;
    const auto overhead = frame::frame_overhead(mac != nullptr) + frame::safe_chunk_overhead() +
                          static_cast<std::size_t>(std::lround(turnaround_bytes));
    // Parity sized for independent errors does not repair bursts (a lost air packet takes many shards).
    plan =
        fec::plan_frames(*rate, overhead, cfg.min_frame_payload, cfg.max_frame_payload, cfg.fec && !bursty);
    parity_cache.fill(0xFFFF);
    stats.fec = plan.fec;
    stats.fec_shard_bytes = plan.shard_bytes;
    stats.peer_suggested_payload = plan.payload;
}

std::vector<std::uint8_t> Transport::Impl::to_wire(std::vector<std::uint8_t> plain, const FrameMac* key,
                                                   const MacContext& ctx) {
    // Plain frames, unless the plan says shards or the frame is far longer than the plan's plain frames (a
    // Safe segment cut before the error rate was known keeps its length when it is sent again).
    const std::size_t plain_bytes = plain.size() + frame::frame_overhead(key != nullptr);
    const bool oversize =
        plan.shard_bytes > 0 && plain_bytes > 2 * (plan.payload + frame::frame_overhead(true));
    if (!plan.fec && !oversize) {
        return frame::seal(std::move(plain), key, ctx);
    }
    const auto sealed = frame::seal_plain(std::move(plain), key, ctx);
    std::size_t n = fec::data_shards_for(sealed.size(), plan.shard_bytes);
    fec::ShardGeometry g{plan.shard_bytes, n, 0};
    if (n <= fec::kMaxShards) {
        auto& parity = parity_cache[n];
        if (parity == 0xFFFF) {
            parity = static_cast<std::uint16_t>(fec::parity_for(n, plan.shard_survival));
        }
        g.parity = parity;
    }
    if (g.data + g.parity > fec::kMaxShards) {
        g = fec::fit_frame(sealed.size(), *plan_rate, plan.shard_bytes);
    }
    std::vector<std::uint8_t> out;
    out.reserve((g.data + g.parity) * (g.shard_bytes + fec::kShardOverhead));
    fec::encode_frame(sealed, static_cast<std::uint8_t>(next_group++ & 0x3FU), g.shard_bytes, g.parity, out);
    ++stats.fec_frames_sent;
    return out;
}

}  // namespace airseg::groundlink
