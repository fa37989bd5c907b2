#include "bench/linkbench/seed_protocol.hpp"

#include <algorithm>
#include <array>

namespace airseg::linkbench::seed {

namespace {

constexpr std::size_t kHeader = 5;  // type, seq(2), frag_seq, frag_total
constexpr std::size_t kCrc = 4;
constexpr std::size_t kMaxCompletedRemembered = 1024;

constexpr std::array<std::uint32_t, 256> make_crc_table() {
    std::array<std::uint32_t, 256> table{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) {
            c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
        }
        table[i] = c;
    }
    return table;
}

constexpr auto kCrcTable = make_crc_table();

std::vector<std::uint8_t> header(FrameType type, std::uint16_t seq, std::uint8_t frag, std::uint8_t total) {
    return {static_cast<std::uint8_t>(type), static_cast<std::uint8_t>(seq & 0xFF),
            static_cast<std::uint8_t>(seq >> 8), frag, total};
}

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
    std::uint32_t c = 0xFFFFFFFFU;
    for (std::uint8_t b : bytes) {
        c = kCrcTable[(c ^ b) & 0xFFU] ^ (c >> 8);
    }
    return c ^ 0xFFFFFFFFU;
}

std::vector<std::uint8_t> encode_frame(std::span<const std::uint8_t> body) {
    const std::uint32_t crc = crc32(body);
    std::vector<std::uint8_t> out;
    out.reserve(body.size() + body.size() / 16 + 8);
    out.push_back(kDle);
    auto put = [&out](std::uint8_t b) {
        if (b == kDle) {
            out.push_back(kDle);
        }
        out.push_back(b);
    };
    for (std::uint8_t b : body) {
        put(b);
    }
    for (int shift = 0; shift < 32; shift += 8) {
        put(static_cast<std::uint8_t>((crc >> shift) & 0xFFU));
    }
    out.push_back(kDle);
    out.push_back(kEtx);
    return out;
}

SeedEndpoint::SeedEndpoint(SeedConfig config) : config_(config) {}

std::vector<std::vector<std::uint8_t>> SeedEndpoint::fragment(FrameType type, std::uint16_t seq,
                                                              std::span<const std::uint8_t> msg) const {
    const std::size_t per = config_.max_packet_size;
    const std::size_t count = std::max<std::size_t>(1, (msg.size() + per - 1) / per);
    std::vector<std::vector<std::uint8_t>> frames;
    if (count > 255) {
        return frames;
    }
    for (std::size_t i = 0; i < count; ++i) {
        auto body = header(type, seq, static_cast<std::uint8_t>(i + 1), static_cast<std::uint8_t>(count));
        auto part = msg.subspan(i * per, std::min(per, msg.size() - i * per));
        body.insert(body.end(), part.begin(), part.end());
        frames.push_back(encode_frame(body));
    }
    return frames;
}

bool SeedEndpoint::send_safe(std::span<const std::uint8_t> msg, TimePoint /*now*/) {
    auto frames = fragment(FrameType::Safe, next_safe_seq_, msg);
    if (frames.empty()) {
        return false;
    }
    const std::uint16_t seq = next_safe_seq_++;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const FragmentKey key{seq, static_cast<std::uint8_t>(i + 1)};
        sent_[key] = SentFragment{std::move(frames[i]), TimePoint{}, true};
        safe_queue_.push_back(key);
    }
    unacked_fragments_[seq] = frames.size();
    return true;
}

bool SeedEndpoint::send_fast(std::span<const std::uint8_t> msg, TimePoint /*now*/) {
    auto frames = fragment(FrameType::Fast, next_fast_seq_, msg);
    if (frames.empty()) {
        return false;
    }
    ++next_fast_seq_;
    if (fast_queue_.size() >= config_.max_message_queue) {
        fast_queue_.pop_front();  // the seed keeps the newest values
        ++stats_.fast_dropped_queue;
    }
    fast_queue_.push_back(std::move(frames));
    return true;
}

std::optional<std::vector<std::uint8_t>> SeedEndpoint::poll_transmit(TimePoint now) {
    std::optional<std::vector<std::uint8_t>> out;
    if (!control_queue_.empty()) {
        out = std::move(control_queue_.front());
        control_queue_.pop_front();
    }
    while (!out && !safe_queue_.empty()) {
        const FragmentKey key = safe_queue_.front();
        safe_queue_.pop_front();
        auto it = sent_.find(key);
        if (it == sent_.end() || !it->second.queued) {
            continue;  // acknowledged while waiting
        }
        it->second.queued = false;
        it->second.sent_at = now;
        ++stats_.safe_fragments_sent;
        out = it->second.frame;
    }
    if (!out && fast_in_progress_.empty() && !fast_queue_.empty()) {
        for (auto& f : fast_queue_.front()) {
            fast_in_progress_.push_back(std::move(f));
        }
        fast_queue_.pop_front();
    }
    if (!out && !fast_in_progress_.empty()) {
        out = std::move(fast_in_progress_.front());
        fast_in_progress_.pop_front();
    }
    if (out) {
        ++stats_.frames_sent;
        stats_.bytes_sent += out->size();
    }
    return out;
}

void SeedEndpoint::handle_timeout(TimePoint now) {
    for (auto& [key, frag] : sent_) {
        if (!frag.queued && now - frag.sent_at >= config_.time_to_resend) {
            frag.queued = true;
            safe_queue_.push_back(key);
            ++stats_.resent_on_timeout;
        }
    }
    for (auto it = fast_rx_.begin(); it != fast_rx_.end();) {
        if (now - it->second.started >= config_.fast_reassembly_timeout) {
            ++stats_.fast_dropped_incomplete;
            it = fast_rx_.erase(it);
        } else {
            ++it;
        }
    }
}

TimePoint SeedEndpoint::poll_timeout() const {
    TimePoint next = kNever;
    for (const auto& [key, frag] : sent_) {
        if (!frag.queued) {
            next = std::min(next, frag.sent_at + config_.time_to_resend);
        }
    }
    for (const auto& [seq, r] : fast_rx_) {
        next = std::min(next, r.started + config_.fast_reassembly_timeout);
    }
    return next;
}

std::optional<SeedMessage> SeedEndpoint::poll_message() {
    if (delivered_.empty()) {
        return std::nullopt;
    }
    SeedMessage m = std::move(delivered_.front());
    delivered_.pop_front();
    return m;
}

std::size_t SeedEndpoint::safe_pending() const {
    return unacked_fragments_.size();
}

void SeedEndpoint::handle_bytes(std::span<const std::uint8_t> bytes, TimePoint now) {
    for (std::uint8_t b : bytes) {
        if (raw_.size() >= config_.max_raw_frame) {
            raw_.clear();
            pending_dle_ = false;
            ++stats_.raw_overflows;
        }
        raw_.push_back(b);
        if (b == kDle) {
            pending_dle_ = !pending_dle_;  // a second DLE pairs with the first: a data byte
            continue;
        }
        if (b == kEtx && pending_dle_) {
            // Everything since the previous DLE ETX is one frame: drop lone DLEs, undouble DLE DLE.
            std::vector<std::uint8_t> body;
            body.reserve(raw_.size());
            for (std::size_t i = 0; i + 2 < raw_.size(); ++i) {
                if (raw_[i] != kDle) {
                    body.push_back(raw_[i]);
                } else if (i + 3 < raw_.size() && raw_[i + 1] == kDle) {
                    body.push_back(kDle);
                    ++i;
                }
            }
            raw_.clear();
            pending_dle_ = false;
            on_frame(body, now);
            continue;
        }
        pending_dle_ = false;
    }
}

void SeedEndpoint::on_frame(std::span<const std::uint8_t> f, TimePoint now) {
    bool valid = f.size() >= kHeader + kCrc;
    if (valid) {
        const auto n = f.size() - kCrc;
        const std::uint32_t got =
            static_cast<std::uint32_t>(f[n]) | static_cast<std::uint32_t>(f[n + 1]) << 8 |
            static_cast<std::uint32_t>(f[n + 2]) << 16 | static_cast<std::uint32_t>(f[n + 3]) << 24;
        valid = crc32(f.first(n)) == got;
    }
    if (f.size() < kHeader) {
        ++stats_.crc_errors;
        return;
    }
    const FragmentKey key{static_cast<std::uint16_t>(f[1] | f[2] << 8), f[3]};
    const std::uint8_t total = f[4];
    if (!valid) {
        ++stats_.crc_errors;
        if (f[0] == static_cast<std::uint8_t>(FrameType::Safe)) {
            queue_control(FrameType::Nack, key, total);  // the header may itself be damaged: best guess
        }
        return;
    }
    const auto data = f.subspan(kHeader, f.size() - kHeader - kCrc);
    switch (static_cast<FrameType>(f[0])) {
        case FrameType::Ack: {
            ++stats_.acks_received;
            if (sent_.erase(key) != 0) {
                auto it = unacked_fragments_.find(key.seq);
                if (it != unacked_fragments_.end() && --it->second == 0) {
                    unacked_fragments_.erase(it);
                }
            }
            return;
        }
        case FrameType::Nack:
            ++stats_.nacks_received;
            if (auto it = sent_.find(key); it != sent_.end() && !it->second.queued) {
                ++stats_.resent_on_nack;
                requeue(key);
            }
            return;
        case FrameType::Safe:
        case FrameType::Fast:
            on_data(static_cast<FrameType>(f[0]), key, total, data, now);
            return;
    }
    ++stats_.crc_errors;  // a valid CRC around an unknown type
}

void SeedEndpoint::on_data(FrameType type, FragmentKey key, std::uint8_t total,
                           std::span<const std::uint8_t> data, TimePoint now) {
    const bool safe = type == FrameType::Safe;
    if (safe) {
        queue_control(FrameType::Ack, key, total);
        if (completed_.count(key.seq) != 0) {
            ++stats_.safe_duplicates;
            return;
        }
    }
    if (key.frag == 0 || total == 0 || key.frag > total) {
        return;
    }
    auto& table = safe ? safe_rx_ : fast_rx_;
    Reassembly& r = table[key.seq];
    if (r.total == 0) {
        r.total = total;
        r.started = now;
    }
    if (r.total != total) {
        return;
    }
    r.parts.emplace(key.frag, std::vector<std::uint8_t>(data.begin(), data.end()));
    if (r.parts.size() == r.total) {
        SeedMessage m{safe, {}};
        for (auto& [i, part] : r.parts) {
            m.bytes.insert(m.bytes.end(), part.begin(), part.end());
        }
        delivered_.push_back(std::move(m));
        table.erase(key.seq);
        if (safe) {
            completed_.insert(key.seq);
            completed_order_.push_back(key.seq);
            if (completed_order_.size() > kMaxCompletedRemembered) {
                completed_.erase(completed_order_.front());
                completed_order_.pop_front();
            }
        }
        return;
    }
    if (safe && safe_rx_.size() > config_.max_partial_safe) {
        safe_rx_.erase(safe_rx_.begin());
        ++stats_.safe_partials_dropped;
    }
}

void SeedEndpoint::queue_control(FrameType type, FragmentKey key, std::uint8_t total) {
    control_queue_.push_back(encode_frame(header(type, key.seq, key.frag, total)));
    ++(type == FrameType::Ack ? stats_.acks_sent : stats_.nacks_sent);
}

void SeedEndpoint::requeue(FragmentKey key) {
    sent_[key].queued = true;
    safe_queue_.push_back(key);
}

}  // namespace airseg::linkbench::seed
