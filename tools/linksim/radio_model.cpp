#include "tools/linksim/radio_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace airseg::linksim {

namespace {

Duration ceil_ns(double ns) {
    return std::chrono::nanoseconds(static_cast<std::int64_t>(std::ceil(ns)));
}

// Portable uniform [0, 1): the standard distributions are not specified bit-exactly across libraries.
double uniform01(std::mt19937_64& rng) {
    return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

std::uint8_t random_bit(std::mt19937_64& rng) {
    return static_cast<std::uint8_t>(1U << (rng() >> 61));
}

}  // namespace

RadioModel::RadioModel(RadioConfig config, TimePoint start)
    : config_(std::move(config)),
      start_(start),
      now_(start),
      // Rounded up so the modelled rate never exceeds the nominal one.
      serial_byte_time_(ceil_ns(1e9 / config_.serial_bytes_per_second())),
      air_ns_per_byte_(1e9 / config_.air_bytes_per_second()) {
    if (auto error = config_.validate(); !error.empty()) {
        throw std::invalid_argument("radio model: " + error);
    }
    for (Side s : {Side::A, Side::B}) {
        Direction& d = dir(s);
        std::seed_seq seq{config_.seed, static_cast<std::uint64_t>(index(s))};
        d.rng.seed(seq);
        d.serial_in_free = start;
        d.serial_out_free = start;
        d.adapter_sent = start;
        for (const Outage& o : config_.impairment[index(s)].outages) {
            d.outages.push_back({start + o.start, start + o.start + o.length});
        }
    }
    for (Channel& ch : channels_) {
        ch.free_at = start;
    }
}

std::size_t RadioModel::push(Side from, std::span<const std::uint8_t> bytes, TimePoint now) {
    advance(now);
    Direction& d = dir(from);
    if (d.down) {
        d.stats.down_dropped += bytes.size();
        return bytes.size();
    }
    const std::size_t space = config_.host_buffer - std::min(config_.host_buffer, d.serial_in.size());
    const std::size_t n = std::min(space, bytes.size());
    TimePoint t = std::max(now, d.serial_in_free);
    for (std::size_t i = 0; i < n; ++i) {
        t += serial_byte_time_;
        d.serial_in.push_back({t, bytes[i]});
    }
    d.serial_in_free = t;
    d.stats.bytes_in += n;
    d.stats.bytes_refused += bytes.size() - n;
    return n;
}

std::size_t RadioModel::serial_space(Side from, TimePoint now) {
    advance(now);
    const Direction& d = dir(from);
    return config_.host_buffer - std::min(config_.host_buffer, d.serial_in.size());
}

std::vector<std::uint8_t> RadioModel::poll_output(Side to, TimePoint now) {
    advance(now);
    // Bytes for host `to` travel in the direction sent by the other side.
    Direction& d = dir(other(to));
    std::vector<std::uint8_t> out;
    while (!d.serial_out.empty() && d.serial_out.front().at <= now) {
        const std::optional<Packet> p = next_handover(d, to);
        if (p->at > now) {
            break;
        }
        for (std::size_t i = 0; i < p->bytes; ++i) {
            out.push_back(d.serial_out.front().byte);
            d.serial_out.pop_front();
        }
        d.adapter_sent = p->at;
    }
    d.stats.bytes_out += out.size();
    return out;
}

std::optional<RadioModel::Packet> RadioModel::next_handover(const Direction& d, Side to) const {
    if (d.serial_out.empty()) {
        return std::nullopt;
    }
    const TimePoint first = d.serial_out.front().at;
    const Duration latency = config_.usb_latency[index(to)];
    if (latency <= Duration::zero()) {
        return Packet{first, 1};
    }
    // The timer expires every `latency` after the last packet (an empty one when nothing arrived); the
    // first byte leaves at the first expiry after it arrived, or earlier with a packet's worth behind it.
    TimePoint expiry = d.adapter_sent + latency;
    if (expiry < first) {
        expiry += ((first - expiry + latency - Duration{1}) / latency) * latency;
    }
    const std::size_t full = config_.usb_packet;
    if (d.serial_out.size() >= full && d.serial_out[full - 1].at < expiry) {
        return Packet{d.serial_out[full - 1].at, full};
    }
    const auto end = std::upper_bound(d.serial_out.begin(), d.serial_out.end(), expiry,
                                      [](TimePoint t, const Timed& x) { return t < x.at; });
    return Packet{expiry, static_cast<std::size_t>(end - d.serial_out.begin())};
}

TimePoint RadioModel::poll_timeout() const {
    TimePoint next = kNever;
    for (Side to : {Side::A, Side::B}) {
        if (auto p = next_handover(dir(other(to)), to)) {
            next = std::min(next, p->at);
        }
    }
    for (Side s : {Side::A, Side::B}) {
        if (auto ready = ready_time(dir(s), channel_of(s).free_at)) {
            next = std::min(next, *ready);
        }
    }
    return next;
}

void RadioModel::add_outage(Side from, TimePoint start, Duration length) {
    dir(from).outages.push_back({start, start + length});
}

void RadioModel::set_radio_down(Side radio, bool down, TimePoint now) {
    advance(now);
    Direction& d = dir(radio);
    d.down = down;
    if (!down) {
        return;
    }
    d.stats.down_dropped += d.fifo.size() + d.serial_in.size();
    d.fifo.clear();
    d.serial_in.clear();
    d.serial_in_free = now;
    // What the radio had received but not yet written to its host is gone with it.
    Direction& incoming = dir(other(radio));
    while (!incoming.serial_out.empty() && incoming.serial_out.back().at > now) {
        incoming.serial_out.pop_back();
    }
    incoming.serial_out_free = std::min(incoming.serial_out_free, now);
}

double RadioModel::air_utilisation(Side from, TimePoint now) const {
    const auto elapsed = now - start_;
    if (elapsed <= Duration::zero()) {
        return 0.0;
    }
    const double u =
        std::chrono::duration<double>(channel_of(from).busy) / std::chrono::duration<double>(elapsed);
    return std::min(1.0, u);
}

void RadioModel::advance(TimePoint now) {
    if (now < now_) {
        now = now_;  // time never runs backwards inside the model
    }
    now_ = now;
    if (config_.duplex == Duplex::Half) {
        const Side both[] = {Side::A, Side::B};
        advance_channel(channels_[0], both, now);
    } else {
        const Side a[] = {Side::A};
        const Side b[] = {Side::B};
        advance_channel(channels_[0], a, now);
        advance_channel(channels_[1], b, now);
    }
    absorb(dir(Side::A), now);
    absorb(dir(Side::B), now);
}

void RadioModel::advance_channel(Channel& ch, std::span<const Side> senders, TimePoint now) {
    while (ch.free_at <= now) {
        const TimePoint t = ch.free_at;
        std::optional<TimePoint> earliest;
        for (Side s : senders) {
            absorb(dir(s), t);
            if (auto r = ready_time(dir(s), t); r && (!earliest || *r < *earliest)) {
                earliest = r;
            }
        }
        if (!earliest || *earliest > now) {
            ch.free_at = now;  // idle: a later push may make either side ready
            return;
        }
        if (*earliest > t) {
            ch.free_at = *earliest;
            continue;
        }
        // Several sides ready at once: alternate, as a TDM radio does.
        std::optional<Side> chosen;
        for (Side s : senders) {
            if (ready_time(dir(s), t) == t && (!chosen || ch.last_sender == chosen)) {
                chosen = s;
            }
        }
        transmit(*chosen, ch, t);
    }
}

void RadioModel::absorb(Direction& d, TimePoint until) {
    while (!d.serial_in.empty() && d.serial_in.front().at <= until) {
        if (d.fifo.size() >= config_.radio_buffer) {
            ++d.stats.overflow_dropped;
        } else {
            d.fifo.push_back(d.serial_in.front().byte);
        }
        d.serial_in.pop_front();
    }
}

std::optional<TimePoint> RadioModel::ready_time(const Direction& d, TimePoint free_at) const {
    if (d.down || (d.fifo.empty() && d.serial_in.empty())) {
        return std::nullopt;
    }
    const std::size_t target = std::min(config_.max_air_packet, config_.radio_buffer);
    if (d.fifo.size() >= target || d.serial_in.empty()) {
        return free_at;
    }
    // Gather: wait for a full packet or for the host to stop writing, whichever comes first.
    const std::size_t needed = std::min(target - d.fifo.size(), d.serial_in.size());
    return std::max(free_at, d.serial_in[needed - 1].at);
}

void RadioModel::transmit(Side from, Channel& ch, TimePoint decided_at) {
    Direction& d = dir(from);
    TimePoint begin = decided_at;
    if (config_.duplex == Duplex::Half && ch.last_sender && *ch.last_sender != from) {
        begin += config_.turnaround;
        ch.busy += config_.turnaround;
    }
    const std::size_t n = std::min(d.fifo.size(), config_.max_air_packet);
    std::vector<std::uint8_t> packet(d.fifo.begin(), d.fifo.begin() + static_cast<std::ptrdiff_t>(n));
    d.fifo.erase(d.fifo.begin(), d.fifo.begin() + static_cast<std::ptrdiff_t>(n));
    const Duration airtime = ceil_ns(static_cast<double>(n + config_.air_packet_overhead) * air_ns_per_byte_);
    const TimePoint end = begin + airtime;
    ch.free_at = end;
    ch.last_sender = from;
    ch.busy += airtime;
    d.stats.air_time += airtime;
    ++d.stats.packets_sent;
    deliver(from, std::move(packet), begin, end);
}

void RadioModel::deliver(Side from, std::vector<std::uint8_t> packet, TimePoint begin, TimePoint end) {
    Direction& d = dir(from);
    const DirectionImpairment& imp = config_.impairment[index(from)];
    if (dir(other(from)).down || in_outage(d, begin, end)) {
        ++d.stats.outage_packets_lost;
        return;
    }
    if (chance(d, imp.frame_loss)) {
        ++d.stats.packets_lost;
        return;
    }
    const TimePoint ready = end + imp.latency;
    // Capacity counts only bytes not yet written to the host by the time this packet is ready.
    auto pending_begin = std::upper_bound(d.serial_out.begin(), d.serial_out.end(), ready,
                                          [](TimePoint t, const Timed& x) { return t < x.at; });
    auto pending = static_cast<std::size_t>(d.serial_out.end() - pending_begin);
    for (std::uint8_t b : packet) {
        if (chance(d, imp.byte_loss)) {
            ++d.stats.bytes_lost;
            continue;
        }
        const std::uint8_t original = b;
        if (chance(d, imp.byte_corruption)) {
            b ^= random_bit(d.rng);
        }
        if (imp.bit_error_rate > 0.0) {
            for (int bit = 0; bit < 8; ++bit) {
                if (chance(d, imp.bit_error_rate)) {
                    b ^= static_cast<std::uint8_t>(1U << bit);
                }
            }
        }
        if (b != original) {
            ++d.stats.bytes_corrupted;
        }
        if (pending >= config_.radio_buffer) {
            ++d.stats.rx_overflow_dropped;
            continue;
        }
        const TimePoint at = std::max(ready, d.serial_out_free) + serial_byte_time_;
        d.serial_out_free = at;
        d.serial_out.push_back({at, b});
        ++pending;
    }
}

bool RadioModel::in_outage(const Direction& d, TimePoint begin, TimePoint end) const {
    return std::any_of(d.outages.begin(), d.outages.end(),
                       [&](const Interval& o) { return begin < o.end && o.begin < end; });
}

bool RadioModel::chance(Direction& d, double p) {
    if (p <= 0.0) {
        return false;
    }
    return uniform01(d.rng) < p;
}

}  // namespace airseg::linksim
