#include <algorithm>
#include <ostream>
#include <string>
#include <vector>

#include "services/groundlink/transport/frame.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

std::vector<std::string> TransportConfig::validate() const {
    std::vector<std::string> e;
    auto need = [&e](bool ok, const std::string& what) {
        if (!ok) {
            e.push_back("groundlink.transport." + what);
        }
    };
    need(link_rate_bytes_per_s >= 10.0 && link_rate_bytes_per_s <= 1e8, "link_rate must be 10..1e8 bytes/s");
    need(paths == 1 || paths == 2, "paths must be 1 or 2");
    need(!second_key || key, "second_key needs key");
    need(!second_key || !key || *second_key != *key, "second_key must differ from key");
    need(path_mode == PathMode::Single || paths == 2, "path_mode split/redundant needs paths: 2");
    need(path_mode != PathMode::Single || paths == 1, "path_mode single needs paths: 1");
    need(split_tx_path < paths, "split_tx_path must be a path index below paths");
    need(max_frame_payload >= 32 && max_frame_payload <= 4096, "max_frame_payload must be 32..4096");
    need(min_frame_payload >= 16 && min_frame_payload <= max_frame_payload,
         "min_frame_payload must be 16..max_frame_payload");
    need(latency_frame_payload >= min_frame_payload && latency_frame_payload <= max_frame_payload,
         "latency_frame_payload must be min_frame_payload..max_frame_payload");
    need(latency_hold >= Duration::zero(), "latency_hold must not be negative");
    need(air_turnaround >= Duration::zero() && air_turnaround <= std::chrono::milliseconds(100),
         "air_turnaround must be 0..100 ms");
    need(air_rate_bytes_per_s == 0.0 || (air_rate_bytes_per_s >= 10.0 && air_rate_bytes_per_s <= 1e8),
         "air_rate must be 0 (the link rate) or 10..1e8 bytes/s");
    need(air_packet_payload == 0 || (air_packet_payload >= 8 && air_packet_payload <= 4096),
         "air_packet must be 0 (no packets) or 8..4096 bytes");
    need(air_packet_overhead <= 256, "air_packet_overhead must be 0..256 bytes");
    need(air_packet_payload != 0 || air_packet_overhead == 0, "air_packet_overhead needs air_packet");
    need(radio_buffer_bytes == 0 || (radio_buffer_bytes >= 64 && radio_buffer_bytes <= (1U << 24)),
         "radio_buffer must be 0 (unknown) or 64..16777216 bytes");
    need(urgent_pacing >= 0.5 && urgent_pacing <= 1.0, "urgent_pacing must be 0.5..1");
    need(priorities >= 1 && priorities <= kMaxPriorities, "priorities must be 1..8");
    double shares = 0.0;
    for (std::size_t i = 0; i < kMaxPriorities; ++i) {
        need(min_share[i] >= 0.0 && min_share[i] <= 0.5,
             "min_share[" + std::to_string(i) + "] must be 0..0.5");
        if (i < priorities) {
            shares += min_share[i];
        }
    }
    need(shares <= 0.8, "min_share of the configured priorities must add up to at most 0.8");
    need(safe_window >= 1 && safe_window <= kMaxSafeWindow, "safe_window must be 1..128");
    need(max_message_size >= 1 && max_message_size <= kMaxFragments * max_frame_payload,
         "max_message_size must be 1..255 x max_frame_payload");
    need(safe_queue_bytes >= max_message_size,
         "safe_queue_bytes must hold at least one max_message_size message");
    need(retransmit_share > 0.0 && retransmit_share <= 1.0, "retransmit_share must be in (0, 1]");
    need(ack_delay >= Duration::zero() && ack_delay <= std::chrono::seconds(1), "ack_delay must be 0..1 s");
    need(ack_every >= 1, "ack_every must be at least 1");
    need(rto_min > Duration::zero() && rto_min <= rto_max, "rto_min must be positive and at most rto_max");
    need(rto_initial > Duration::zero(), "rto_initial must be positive");
    need(fast_queue_cap >= 1 && fast_queue_cap <= 4096, "fast_queue_cap must be 1..4096");
    need(fast_reassembly_timeout > Duration::zero(), "fast_reassembly_timeout must be positive");
    need(keepalive_interval > Duration::zero(), "keepalive_interval must be positive");
    need(hello_interval > Duration::zero(), "hello_interval must be positive");
    need(link_down_after > keepalive_interval * 3 / 2,
         "link_down_after must be longer than 1.5 x keepalive_interval (an idle path's longest gap between "
         "probes)");
    need(link_up_frames >= 1 && link_up_frames <= 100, "link_up_frames must be 1..100");
    need(delivery_queue_cap >= 1, "delivery_queue_cap must be at least 1");
    need(boot_nonce != 0, "boot_nonce must not be 0 (the adapter supplies a random value)");
    return e;
}

double TransportConfig::carried_rate_bytes_per_s() const {
    const double air = air_rate_bytes_per_s > 0.0 ? air_rate_bytes_per_s : link_rate_bytes_per_s;
    const double payload_share = air_packet_payload == 0
                                     ? 1.0
                                     : static_cast<double>(air_packet_payload) /
                                           static_cast<double>(air_packet_payload + air_packet_overhead);
    return std::min(link_rate_bytes_per_s, air * payload_share);
}

std::ostream& operator<<(std::ostream& os, SendResult r) {
    switch (r) {
        case SendResult::Accepted:
            return os << "accepted";
        case SendResult::Replaced:
            return os << "replaced";
        case SendResult::DroppedOldest:
            return os << "dropped_oldest";
        case SendResult::QueueFull:
            return os << "queue_full";
        case SendResult::TooLarge:
            return os << "too_large";
        case SendResult::BadPriority:
            return os << "bad_priority";
    }
    return os << "SendResult(" << static_cast<int>(r) << ")";
}

std::ostream& operator<<(std::ostream& os, TransportEvent::Kind k) {
    using K = TransportEvent::Kind;
    switch (k) {
        case K::SessionEstablished:
            return os << "session_established";
        case K::PeerRestarted:
            return os << "peer_restarted";
        case K::LinkUp:
            return os << "link_up";
        case K::LinkDown:
            return os << "link_down";
        case K::PathUp:
            return os << "path_up";
        case K::PathDown:
            return os << "path_down";
        case K::SafeResent:
            return os << "safe_resent";
    }
    return os << "TransportEvent::Kind(" << static_cast<int>(k) << ")";
}

}  // namespace airseg::groundlink
