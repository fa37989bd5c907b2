#include "services/groundlink/transport/transport.hpp"

#include <algorithm>
#include <stdexcept>

#include "services/groundlink/transport/transport_impl.hpp"

namespace airseg::groundlink {
namespace {

TransportConfig checked(TransportConfig c) {
    const auto problems = c.validate();
    if (!problems.empty()) {
        std::string all = "groundlink: invalid transport configuration:";
        for (const auto& p : problems) {
            all += "\n  " + p;
        }
        throw std::invalid_argument(all);
    }
    return c;
}

// Air packet of a SiK-class radio, when the configuration does not say (the largest at the default
// settings): the stage of a frame's crossing that does not overlap the others.
constexpr std::size_t kTypicalAirPacket = 252;

}  // namespace

Transport::Impl::Impl(TransportConfig config, TimePoint now)
    : cfg(checked(std::move(config))),
      air_estimate(cfg.carried_rate_bytes_per_s(), now),
      current_time(now),
      reassembly(cfg.fast_reassembly_timeout, cfg.max_message_size),
      rtt(cfg.rto_initial, cfg.rto_min, cfg.rto_max, cfg.ack_delay, frame_time(cfg.max_frame_payload + 32)) {
    if (cfg.key) {
        keys[0] = std::make_unique<FrameMac>(*cfg.key);
        mac = keys[0].get();
    }
    if (cfg.second_key) {
        keys[1] = std::make_unique<FrameMac>(*cfg.second_key);
    }
    stats.authenticated = mac != nullptr;
    candidate = cfg.boot_nonce;
    const std::size_t max_encoded = cobs_max_encoded(cfg.max_frame_payload + 256);
    for (std::size_t p = 0; p < cfg.paths; ++p) {
        paths.emplace_back(max_encoded);
        paths.back().next_free = now;
        paths.back().next_hello = now;
        paths.back().last_sent = now;
        paths.back().last_hello = now - cfg.hello_interval;
    }
    for (std::size_t l = 0; l < cfg.priorities; ++l) {
        senders.emplace_back(cfg.safe_window, cfg.safe_queue_bytes, cfg.max_message_size);
        receivers.emplace_back(cfg.safe_window, cfg.max_message_size);
        fast.emplace_back(cfg.fast_queue_cap);
    }
    acks.resize(cfg.priorities);
    backoff.resize(cfg.priorities, 0);
    last_report_time = now;
    refresh(now);
}

SendResult Transport::Impl::send_safe(std::uint8_t priority, std::span<const std::uint8_t> msg,
                                      TimePoint now) {
    current_time = std::max(current_time, now);
    if (priority >= cfg.priorities) {
        return SendResult::BadPriority;
    }
    const SendResult r = senders[priority].enqueue(msg);
    if (r == SendResult::Accepted) {
        ++stats.tx_safe.messages;
        stats.tx_safe.bytes += msg.size();
        if (priority + 1U < cfg.priorities) {
            mark_urgent(current_time);
        }
    }
    refresh(current_time);
    return r;
}

SendResult Transport::Impl::send_fast(std::uint8_t priority, std::uint16_t topic,
                                      std::span<const std::uint8_t> msg, TimePoint now) {
    current_time = std::max(current_time, now);
    if (priority >= cfg.priorities) {
        return SendResult::BadPriority;
    }
    if (msg.size() > cfg.max_message_size) {
        return SendResult::TooLarge;
    }
    const SendResult r = fast[priority].push(topic, msg);
    ++stats.tx_fast.messages;
    stats.tx_fast.bytes += msg.size();
    if (r == SendResult::Replaced) {
        ++stats.tx_fast.replaced;
    } else if (r == SendResult::DroppedOldest) {
        ++stats.tx_fast.drops;
    }
    mark_urgent(current_time);
    refresh(current_time);
    return r;
}

void Transport::Impl::handle_timeout(TimePoint now) {
    current_time = std::max(current_time, now);
    // The timers are exact as of the latest input: a Safe window or the reassembly is looked through only
    // when its own deadline has come (most wake-ups are for pacing).
    bool expired = false;
    if (current_time >= timers[static_cast<std::size_t>(Timer::Retransmit)]) {
        for (std::size_t l = 0; l < senders.size(); ++l) {
            const std::size_t lost = senders[l].on_timeout(current_time, rtt.rto(backoff[l]));
            if (lost > 0) {
                backoff[l] = std::min(backoff[l] + 1, kMaxBackoff);
                lost_window += static_cast<double>(lost);
                air_estimate.on_lost(lost);
                expired = true;
            }
        }
    }
    if (current_time >= timers[static_cast<std::size_t>(Timer::Reassembly)]) {
        stats.rx_fast.drops += reassembly.expire(current_time);
        expired = true;
    }
    for (std::size_t p = 0; p < paths.size(); ++p) {
        Path& ps = paths[p];
        if (ps.alive && ps.last_heard + cfg.link_down_after <= current_time) {
            ps.alive = false;
            ps.streak = 0;
            push_event(TransportEvent::Kind::PathDown, p);
        }
    }
    update_link_state();
    if (expired) {
        refresh(current_time);
    } else {
        refresh_transmit(current_time);
    }
}

void Transport::Impl::push_event(TransportEvent::Kind kind, std::size_t path, std::uint64_t count) {
    if (events.size() >= kEventCap) {
        events.pop_front();
        ++stats.events_dropped;
    }
    events.push_back(TransportEvent{kind, path, count});
}

void Transport::Impl::update_link_state() {
    const bool any_alive = std::any_of(paths.begin(), paths.end(), [](const Path& p) { return p.alive; });
    const bool up = confirmed && any_alive;
    if (up != link) {
        link = up;
        push_event(up ? TransportEvent::Kind::LinkUp : TransportEvent::Kind::LinkDown);
    }
}

void Transport::Impl::measure_round_trip(Duration rtt_sample, std::size_t segment_bytes, TimePoint now) {
    // A frame that fits one air packet crosses three stages one after the other: the sending host's serial
    // port, the air, the receiving host's port (a longer frame's stages overlap in ways the sizes alone do
    // not tell). A round trip is the segment's frame out and the acknowledging frame back.
    const std::size_t packet = cfg.air_packet_payload != 0 ? cfg.air_packet_payload : kTypicalAirPacket;
    const std::size_t data_frame =
        segment_bytes + frame::frame_overhead(mac != nullptr) + frame::safe_chunk_overhead();
    const bool timed = data_frame <= packet && frame_wire_bytes != 0 && frame_wire_bytes <= packet;
    const auto crossing = [&](std::size_t bytes) {
        const Duration serial = std::chrono::duration_cast<Duration>(
            std::chrono::duration<double>(static_cast<double>(bytes) / cfg.link_rate_bytes_per_s));
        return serial + configured_frame_time(bytes) + serial;
    };
    air_estimate.on_round_trip(
        rtt_sample, timed ? std::optional(crossing(data_frame) + crossing(frame_wire_bytes)) : std::nullopt,
        now);
}

void Transport::Impl::follow_air(TimePoint now) {
    if (!air_estimate.update(now) || !cfg.air_adapt) {
        return;
    }
    carried = air_estimate.carried();
    air_rate_now = configured_air_rate() * carried / air_estimate.configured();
}

void Transport::Impl::refresh(TimePoint now) {
    follow_air(now);
    refresh_transmit(now);
    TimePoint rto = kNever;
    for (std::size_t l = 0; l < senders.size(); ++l) {
        rto = std::min(rto, senders[l].next_timeout(rtt.rto(backoff[l])));
    }
    timers[static_cast<std::size_t>(Timer::Retransmit)] = rto;
    timers[static_cast<std::size_t>(Timer::Reassembly)] = reassembly.next_deadline();
    earliest = *std::min_element(timers.begin(), timers.end());
}

void Transport::Impl::refresh_transmit(TimePoint now) {
    current_time = std::max(current_time, now);
    TimePoint tx = kNever;
    for (std::size_t p = 0; p < paths.size(); ++p) {
        const TimePoint due = content_due(p);
        if (due != kNever) {
            tx = std::min(tx, std::max(due, paths[p].next_free));
        }
    }
    timers[static_cast<std::size_t>(Timer::Transmit)] = tx;
    TimePoint live = kNever;
    for (const Path& ps : paths) {
        if (ps.alive) {
            live = std::min(live, ps.last_heard + cfg.link_down_after);
        }
    }
    if (peer_mask_known && peer_mask_time + cfg.link_down_after > current_time) {
        live = std::min(live, peer_mask_time + cfg.link_down_after);  // path selection changes then
    }
    timers[static_cast<std::size_t>(Timer::Liveness)] = live;
    earliest = *std::min_element(timers.begin(), timers.end());
    refreshed_at = current_time;
}

void Transport::Impl::snapshot_stats() {
    stats.session = established;
    stats.link_up = link;
    stats.srtt_ms = std::chrono::duration<double, std::milli>(rtt.srtt()).count();
    stats.rttvar_ms = std::chrono::duration<double, std::milli>(rtt.rttvar()).count();
    stats.rto_ms = std::chrono::duration<double, std::milli>(rtt.rto()).count();
    stats.rtt_samples = rtt.samples();
    stats.frame_payload = payload_cap();
    stats.byte_error_rate = meter.byte_error_rate().value_or(-1.0);
    stats.peer_byte_error_rate = peer_error.value_or(-1.0);
    stats.frame_loss = sent_window > 0 ? std::min(1.0, lost_window / sent_window) : 0.0;
    stats.air_carried = air_estimate.carried();
    stats.air_delivered = air_estimate.delivered();
    stats.air_turnaround_ms =
        air_estimate.round_trips() == 0
            ? -1.0
            : std::chrono::duration<double, std::milli>(air_estimate.turnaround()).count();
    stats.base_rtt_ms = std::chrono::duration<double, std::milli>(air_estimate.base_rtt()).count();
    stats.air_overflows = air_estimate.overflows();
    stats.air_adapt = cfg.air_adapt;
    std::uint64_t safe_depth = 0;
    std::uint64_t fast_depth = 0;
    for (std::size_t l = 0; l < senders.size(); ++l) {
        safe_depth += senders[l].pending_messages();
        fast_depth += fast[l].size();
    }
    stats.tx_safe.queue_depth = safe_depth;
    stats.tx_fast.queue_depth = fast_depth;
    for (std::size_t p = 0; p < paths.size(); ++p) {
        stats.path[p].alive = paths[p].alive;
        stats.path[p].peer_hears = peer_mask_fresh() && ((peer_mask >> p) & 1U) != 0;
    }
}

// ---- public forwarding

Transport::Transport(TransportConfig config, TimePoint now)
    : impl_(std::make_unique<Impl>(std::move(config), now)) {}
Transport::~Transport() = default;
Transport::Transport(Transport&&) noexcept = default;
Transport& Transport::operator=(Transport&&) noexcept = default;

SendResult Transport::send_safe(std::uint8_t priority, std::span<const std::uint8_t> msg, TimePoint now) {
    return impl_->send_safe(priority, msg, now);
}
SendResult Transport::send_fast(std::uint8_t priority, std::uint16_t topic, std::span<const std::uint8_t> msg,
                                TimePoint now) {
    return impl_->send_fast(priority, topic, msg, now);
}
std::optional<Delivered> Transport::poll_message() {
    if (impl_->deliveries.empty()) {
        return std::nullopt;
    }
    Delivered d = std::move(impl_->deliveries.front());
    impl_->deliveries.pop_front();
    (d.cls == MessageClass::Safe ? impl_->stats.rx_safe : impl_->stats.rx_fast).queue_depth -= 1;
    return d;
}
std::optional<TransportEvent> Transport::poll_event() {
    if (impl_->events.empty()) {
        return std::nullopt;
    }
    TransportEvent e = impl_->events.front();
    impl_->events.pop_front();
    return e;
}
void Transport::handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes, TimePoint now) {
    impl_->handle_bytes(path, bytes, now);
}
std::optional<std::vector<std::uint8_t>> Transport::poll_transmit(std::size_t path, TimePoint now) {
    return impl_->poll_transmit(path, now);
}
TimePoint Transport::poll_timeout() const {
    return impl_->earliest;
}
void Transport::handle_timeout(TimePoint now) {
    impl_->handle_timeout(now);
}
const LinkStats& Transport::stats() const {
    impl_->snapshot_stats();
    return impl_->stats;
}
bool Transport::link_up() const {
    return impl_->link;
}
TimePoint Transport::probe_deadline(std::size_t path) const {
    return impl_->probe_deadline(path);
}
bool Transport::probe_owed(std::size_t path, TimePoint now) const {
    return impl_->probe_deadline(path) != kNever && impl_->probe_owed(path, now);
}
std::size_t Transport::session_key() const {
    return impl_->session_key;
}

bool Transport::session_established() const {
    return impl_->established && impl_->confirmed;
}
const TransportConfig& Transport::config() const {
    return impl_->cfg;
}
std::size_t Transport::safe_pending(std::uint8_t priority) const {
    return priority < impl_->senders.size() ? impl_->senders[priority].pending_messages() : 0;
}

}  // namespace airseg::groundlink
