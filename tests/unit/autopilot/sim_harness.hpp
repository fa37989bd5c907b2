#pragma once
// Two sans-IO parties joined by a simulated serial link, in virtual time that jumps to the next wake-up.
// Each direction serialises frames at the link's byte rate (10 bits per byte), adds a latency, and drops
// whole frames or single bytes with seeded probabilities. The drive loop is bounded so a livelock fails the
// test instead of hanging it. stall_ground() models the ground's process stopped or starved: it is not
// called until then, what comes for it waits, and when it runs again its timer is served before the bytes
// that waited (the worst order; asio may serve a ready timer and a ready read either way).
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "base/time.hpp"

namespace airseg::autopilot::testing {

struct Party {
    std::function<void(std::span<const std::uint8_t>, TimePoint)> receive;
    std::function<std::optional<std::vector<std::uint8_t>>()> transmit;
    std::function<void(TimePoint)> on_timeout;
    std::function<TimePoint()> deadline;
};

struct LinkModel {
    unsigned baud = 115200;
    Duration latency = milliseconds(2);
    double frame_drop = 0.0;  // probability a whole frame is lost
    double byte_drop = 0.0;   // probability each byte is lost
};

class Pipe {
  public:
    Pipe(LinkModel model, std::uint32_t seed) : model_(model), rng_(seed) {}

    void send(std::vector<std::uint8_t> frame, TimePoint now) {
        const TimePoint start = std::max(now, busy_until_);
        busy_until_ =
            start + microseconds(static_cast<std::int64_t>(frame.size()) * 10'000'000 / model_.baud);
        ++frames_;
        if (model_.frame_drop > 0 && coin_(rng_) < model_.frame_drop) {
            ++dropped_frames_;
            return;
        }
        if (model_.byte_drop > 0) {
            std::erase_if(frame, [&](std::uint8_t) { return coin_(rng_) < model_.byte_drop; });
        }
        in_flight_.emplace_back(busy_until_ + model_.latency, std::move(frame));
    }
    TimePoint next() const { return in_flight_.empty() ? kNever : in_flight_.front().first; }
    std::optional<std::vector<std::uint8_t>> pop_due(TimePoint now) {
        if (in_flight_.empty() || in_flight_.front().first > now) {
            return std::nullopt;
        }
        auto f = std::move(in_flight_.front().second);
        in_flight_.pop_front();
        return f;
    }
    void set_model(LinkModel m) { model_ = m; }
    std::uint64_t frames() const { return frames_; }
    std::uint64_t dropped_frames() const { return dropped_frames_; }

  private:
    LinkModel model_;
    std::mt19937 rng_;
    std::uniform_real_distribution<double> coin_{0.0, 1.0};
    TimePoint busy_until_{};
    std::deque<std::pair<TimePoint, std::vector<std::uint8_t>>> in_flight_;
    std::uint64_t frames_ = 0;
    std::uint64_t dropped_frames_ = 0;
};

class Harness {
  public:
    Harness(Party ground, Party vehicle, LinkModel up, LinkModel down, std::uint32_t seed, TimePoint start)
        : ground_(std::move(ground)),
          vehicle_(std::move(vehicle)),
          to_vehicle_(up, seed),
          to_ground_(down, seed * 7919u + 1),
          now_(start) {}

    TimePoint now() const { return now_; }
    /// The ground does not run until `until` (SIGSTOP, starvation).
    void stall_ground(TimePoint until) { ground_stalled_until_ = until; }
    Pipe& to_vehicle() { return to_vehicle_; }
    Pipe& to_ground() { return to_ground_; }

    /// Runs until `done()` holds (true) or virtual time passes `limit` (false).
    bool run_until(const std::function<bool()>& done, TimePoint limit) {
        for (std::size_t steps = 0; steps < 5'000'000; ++steps) {
            flush();
            if (done()) {
                return true;
            }
            const bool stalled = now_ < ground_stalled_until_;
            const TimePoint ground_next =
                stalled ? ground_stalled_until_ : std::min(ground_.deadline(), to_ground_.next());
            const TimePoint t = std::min({ground_next, vehicle_.deadline(), to_vehicle_.next()});
            if (t > limit) {
                now_ = std::max(now_, limit);
                return done();
            }
            now_ = std::max(now_, t);
            while (auto f = to_vehicle_.pop_due(now_)) {
                vehicle_.receive(*f, now_);
            }
            const bool resumed = stalled && now_ >= ground_stalled_until_;
            if (resumed && ground_.deadline() <= now_) {
                ground_.on_timeout(now_);
            }
            if (now_ >= ground_stalled_until_) {
                while (auto f = to_ground_.pop_due(now_)) {
                    ground_.receive(*f, now_);
                }
            }
            if (now_ >= ground_stalled_until_ && ground_.deadline() <= now_) {
                ground_.on_timeout(now_);
            }
            if (vehicle_.deadline() <= now_) {
                vehicle_.on_timeout(now_);
            }
        }
        return false;
    }
    void run_for(Duration d) {
        const TimePoint end = now_ + d;
        run_until([] { return false; }, end);
    }

  private:
    void flush() {
        while (now_ >= ground_stalled_until_) {
            auto f = ground_.transmit();
            if (!f) {
                break;
            }
            to_vehicle_.send(std::move(*f), now_);
        }
        while (auto f = vehicle_.transmit()) {
            to_ground_.send(std::move(*f), now_);
        }
    }

    Party ground_;
    Party vehicle_;
    Pipe to_vehicle_;
    Pipe to_ground_;
    TimePoint now_;
    TimePoint ground_stalled_until_{};
};

}  // namespace airseg::autopilot::testing
