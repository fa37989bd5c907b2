#pragma once
// Periodic housekeeping that may run a little late (progress ticks, status refreshes, pushed telemetry) rides
// on a wake-up the daemon has anyway. On an idle vehicle a wake-up costs more CPU than the work done in it
// (docs/performance.md), and the autopilot's streams and the ground's keepalives wake the daemon several
// times a second: a tick armed with a slack (slack_timer.hpp) runs at the first such wake-up after it is
// due, and on its own timer only when nothing woke the daemon within the slack.
//
// WakeSharing is the process-wide list of ticks due and waiting for a wake-up. Any thread may call it; the
// input paths (serial and UDP reads) call woke() after handling what arrived.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <vector>

#include "base/time.hpp"

namespace airseg {

class WakeSharing {
  public:
    using Id = std::uint64_t;

    /// Registers `run`, called from woke() (on the caller's thread) at the first wake-up at or after `due`.
    /// `run` must only hand work to its owner's strand. Returns the id remove() takes (never 0).
    Id add(TimePoint due, std::function<void()> run);
    /// Forgets a registration; an id already run or removed is ignored.
    void remove(Id id);
    /// The daemon is awake at `now`: runs, and forgets, every registration already due.
    void woke(TimePoint now);

    /// Registrations waiting for their due time or a wake-up.
    [[nodiscard]] std::size_t waiting() const;
    /// Registrations run by woke() so far: ticks that cost no wake-up of their own.
    [[nodiscard]] std::uint64_t shared() const { return shared_.load(std::memory_order_relaxed); }

  private:
    struct Entry {
        Id id;
        TimePoint due;
        std::function<void()> run;
    };
    void update_earliest();

    mutable std::mutex mutex_;
    std::vector<Entry> entries_;
    Id next_id_ = 1;
    // Read without the lock on every input: most wake-ups find nothing due and return at once.
    std::atomic<TimePoint::rep> earliest_{kNever.time_since_epoch().count()};
    std::atomic<std::uint64_t> shared_{0};
};

}  // namespace airseg
