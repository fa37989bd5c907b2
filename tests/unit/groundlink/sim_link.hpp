#pragma once
// Deterministic two-endpoint harness in simulated time: two Transport cores joined by one or two paths, each
// a half-duplex radio pair (both directions share its air time at `rate` bytes/s) with seeded impairments on
// every written frame. The virtual clock jumps to the next poll_timeout() or delivery; the drive loop is
// bounded and reports livelock (too many steps without the clock moving).
#include <algorithm>
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <vector>

#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink::test {

struct Impairments {
    double loss = 0.0;          ///< a written frame vanishes
    double byte_corrupt = 0.0;  ///< each byte is replaced by a random one
    double byte_loss = 0.0;     ///< each byte vanishes (drawn only when set, so other seeds keep their runs)
    double duplicate = 0.0;     ///< a written frame arrives twice
    double reorder = 0.0;       ///< a written frame is held back by up to reorder_delay
    double garbage = 0.0;       ///< random bytes are inserted before a frame
    /// The byte stream of each direction travels in air packets of air_packet_bytes; each is lost whole
    /// with this probability (drawn only when set), taking with it the frames or shards it carries.
    double air_packet_loss = 0.0;
    std::size_t air_packet_bytes = 252;
    Duration reorder_delay = std::chrono::milliseconds(300);
    Duration latency = std::chrono::milliseconds(5);
};

struct PathModel {
    double rate = 5760.0;  ///< air bytes/s, shared by both directions
    Impairments imp;
    bool a_to_b_up = true;  ///< set false to silence one direction
    bool b_to_a_up = true;
};

struct Endpoint {
    std::optional<Transport> core;
    std::vector<Delivered> received;
    std::vector<TransportEvent> events;
};

class SimLink {
  public:
    SimLink(const TransportConfig& a, const TransportConfig& b, std::vector<PathModel> paths,
            std::uint64_t seed)
        : paths_(std::move(paths)), rng_(seed), now_(TimePoint{} + std::chrono::hours(1)) {
        ends_[0].core.emplace(a, now_);
        ends_[1].core.emplace(b, now_);
        air_free_.assign(paths_.size(), now_);
    }

    Endpoint& a() { return ends_[0]; }
    Endpoint& b() { return ends_[1]; }
    Endpoint& end(int i) { return ends_[static_cast<std::size_t>(i)]; }
    PathModel& path(std::size_t p) { return paths_[p]; }
    [[nodiscard]] TimePoint now() const { return now_; }
    [[nodiscard]] bool livelocked() const { return livelock_; }
    /// Bytes written by endpoint `e` to `path` (what pacing bounds).
    [[nodiscard]] std::uint64_t written(int e, std::size_t p) const {
        return written_[static_cast<std::size_t>(e)][p];
    }
    /// How long frames already written to path `p` still queue for air time (the radios' buffer).
    [[nodiscard]] Duration air_backlog(std::size_t p) const {
        return air_free_[p] > now_ ? air_free_[p] - now_ : Duration::zero();
    }
    /// Called in every step for each endpoint (0, 1) after its input and before its transmit poll: what an
    /// adapter does on input before the transport polls.
    std::function<void(int)> before_poll;
    /// Largest single frame written.
    [[nodiscard]] std::size_t largest_frame() const { return largest_frame_; }
    /// Called after every step; return true to stop.
    template <typename Stop>
    bool run_until(TimePoint end, Stop&& stop) {
        std::size_t steps_without_progress = 0;
        TimePoint last = now_;
        while (now_ < end) {
            step();
            if (stop()) {
                return true;
            }
            if (now_ == last) {
                if (++steps_without_progress > 20000) {
                    livelock_ = true;
                    return false;
                }
            } else {
                steps_without_progress = 0;
                last = now_;
            }
            TimePoint next = end;
            for (auto& e : ends_) {
                next = std::min(next, e.core->poll_timeout());
            }
            if (!inflight_.empty()) {
                next = std::min(next, inflight_.begin()->first);
            }
            now_ = std::max(now_, next);
        }
        return false;
    }
    void run_for(Duration d) {
        run_until(now_ + d, [] { return false; });
    }

    /// Restarts endpoint `i` with a fresh core (new boot nonce); its inbox is kept.
    void restart(int i, TransportConfig cfg) { ends_[static_cast<std::size_t>(i)].core.emplace(cfg, now_); }
    /// Injects raw bytes (forgeries, recordings) into endpoint `to` on `path` right now.
    void inject(int to, std::size_t p, const std::vector<std::uint8_t>& bytes) {
        ends_[static_cast<std::size_t>(to)].core->handle_bytes(p, bytes, now_);
        drain();
    }
    /// Every frame endpoint `from` wrote, in order (for replay tests).
    std::vector<std::vector<std::uint8_t>>& recorded(int from) {
        return recorded_[static_cast<std::size_t>(from)];
    }

    void step() {
        // Deliver everything due.
        while (!inflight_.empty() && inflight_.begin()->first <= now_) {
            auto node = inflight_.extract(inflight_.begin());
            const Flight& f = node.mapped();
            ends_[f.to].core->handle_bytes(f.path, f.bytes, now_);
        }
        for (auto& e : ends_) {
            if (e.core->poll_timeout() <= now_) {
                e.core->handle_timeout(now_);
            }
        }
        for (std::size_t from = 0; from < 2; ++from) {
            if (before_poll) {
                before_poll(static_cast<int>(from));
            }
            for (std::size_t p = 0; p < paths_.size(); ++p) {
                while (auto frame = ends_[from].core->poll_transmit(p, now_)) {
                    transmit(from, p, std::move(*frame));
                }
            }
        }
        drain();
    }

  private:
    struct Flight {
        std::size_t to;
        std::size_t path;
        std::vector<std::uint8_t> bytes;
    };

    void drain() {
        for (auto& e : ends_) {
            while (auto m = e.core->poll_message()) {
                e.received.push_back(std::move(*m));
            }
            while (auto ev = e.core->poll_event()) {
                e.events.push_back(*ev);
            }
        }
    }

    double uni() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_); }

    void transmit(std::size_t from, std::size_t p, std::vector<std::uint8_t> bytes) {
        written_[from][p] += bytes.size();
        largest_frame_ = std::max(largest_frame_, bytes.size());
        recorded_[from].push_back(bytes);
        PathModel& pm = paths_[p];
        const auto air = std::chrono::duration_cast<Duration>(
            std::chrono::duration<double>(static_cast<double>(bytes.size()) / pm.rate));
        const TimePoint start = std::max(now_, air_free_[p]);
        air_free_[p] = start + air;
        const bool up = from == 0 ? pm.a_to_b_up : pm.b_to_a_up;
        const Impairments& imp = pm.imp;
        if (!up || uni() < imp.loss) {
            return;
        }
        std::vector<std::uint8_t> out;
        if (uni() < imp.garbage) {
            const int n = 1 + static_cast<int>(uni() * 20);
            for (int i = 0; i < n; ++i) {
                out.push_back(static_cast<std::uint8_t>(rng_()));
            }
        }
        for (std::uint8_t b : bytes) {
            if (imp.air_packet_loss > 0.0) {
                AirStream& s = air_[from][p];
                if (s.bytes % imp.air_packet_bytes == 0) {
                    s.lost = uni() < imp.air_packet_loss;
                }
                ++s.bytes;
                if (s.lost) {
                    continue;
                }
            }
            if (imp.byte_loss > 0.0 && uni() < imp.byte_loss) {
                continue;
            }
            out.push_back(uni() < imp.byte_corrupt ? static_cast<std::uint8_t>(rng_()) : b);
        }
        TimePoint at = start + air + imp.latency;
        if (uni() < imp.reorder) {
            at += std::chrono::duration_cast<Duration>(imp.reorder_delay * uni());
        }
        const std::size_t to = 1 - from;
        if (uni() < imp.duplicate) {
            inflight_.emplace(at + std::chrono::milliseconds(7), Flight{to, p, out});
        }
        inflight_.emplace(at, Flight{to, p, std::move(out)});
    }

    std::vector<PathModel> paths_;
    std::mt19937_64 rng_;
    TimePoint now_;
    std::array<Endpoint, 2> ends_;
    std::vector<TimePoint> air_free_;
    std::multimap<TimePoint, Flight> inflight_;
    std::array<std::array<std::uint64_t, 2>, 2> written_{};
    struct AirStream {
        std::uint64_t bytes = 0;
        bool lost = false;
    };
    std::array<std::map<std::size_t, AirStream>, 2> air_;  // by direction, then path
    std::array<std::vector<std::vector<std::uint8_t>>, 2> recorded_;
    std::size_t largest_frame_ = 0;
    bool livelock_ = false;
};

inline TransportConfig base_config(std::uint64_t nonce, bool keyed = true) {
    TransportConfig c;
    c.boot_nonce = nonce;
    if (keyed) {
        std::array<std::uint8_t, kKeyBytes> k{};
        for (std::size_t i = 0; i < k.size(); ++i) {
            k[i] = static_cast<std::uint8_t>(i * 7 + 3);
        }
        c.key = k;
    }
    return c;
}

inline std::vector<std::uint8_t> pattern(std::size_t n, std::uint32_t id) {
    std::vector<std::uint8_t> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = static_cast<std::uint8_t>((id * 131 + i * 7) & 0xFFU);
    }
    if (n >= 4) {
        v[0] = static_cast<std::uint8_t>(id & 0xFFU);
        v[1] = static_cast<std::uint8_t>((id >> 8) & 0xFFU);
        v[2] = static_cast<std::uint8_t>((id >> 16) & 0xFFU);
        v[3] = static_cast<std::uint8_t>((id >> 24) & 0xFFU);
    }
    return v;
}

inline std::uint32_t id_of(const std::vector<std::uint8_t>& v) {
    return static_cast<std::uint32_t>(v[0]) | (static_cast<std::uint32_t>(v[1]) << 8) |
           (static_cast<std::uint32_t>(v[2]) << 16) | (static_cast<std::uint32_t>(v[3]) << 24);
}

}  // namespace airseg::groundlink::test
