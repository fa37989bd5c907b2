#pragma once
// LineLimiter: how many log lines of one kind may be written, sans-IO (time passed in). Anything a peer can
// make the daemon log (an unknown message, a bad frame, an autopilot's text, a reboot, a refused command)
// goes through one of these, so a peer that repeats itself thousands of times a second costs a few lines per
// period and a count, not megabytes of journal.
//
// Windows: the first line opens a window of `period`; its first `burst` lines pass, the rest are held back
// and counted. The first line after the window has ended opens the next one and carries the count of the
// window before, so the caller can say "… repeated N times in 10 s" before it. A kind that falls silent after
// a flood gets its count from poll_held(), which a periodic tick calls.
#include <cstdint>
#include <optional>

#include "base/time.hpp"

namespace airseg {

struct LineLimiterConfig {
    unsigned burst = 5;  // lines let through per window
    Duration period = seconds(10);
};

class LineLimiter {
  public:
    struct Verdict {
        bool pass = false;       // write this line
        std::uint64_t held = 0;  // lines held back in the window that ended before it (say so first)
    };

    explicit LineLimiter(LineLimiterConfig config = {}) : config_(config) {}

    Verdict admit(TimePoint now) {
        Verdict v;
        if (!open_ || now - window_start_ >= config_.period) {
            v.held = held_;
            held_ = 0;
            open_ = true;
            window_start_ = now;
            passed_ = 0;
        }
        if (passed_ < config_.burst) {
            ++passed_;
            v.pass = true;
        } else {
            ++held_;
            ++held_total_;
        }
        return v;
    }

    /// The count of a window that has ended with lines held back, once; empty otherwise.
    std::optional<std::uint64_t> poll_held(TimePoint now) {
        if (!open_ || held_ == 0 || now - window_start_ < config_.period) {
            return std::nullopt;
        }
        const std::uint64_t held = held_;
        held_ = 0;
        open_ = false;
        return held;
    }

    Duration period() const { return config_.period; }
    /// Lines held back since construction.
    std::uint64_t held_total() const { return held_total_; }

  private:
    LineLimiterConfig config_;
    bool open_ = false;
    TimePoint window_start_{};
    unsigned passed_ = 0;
    std::uint64_t held_ = 0;
    std::uint64_t held_total_ = 0;
};

}  // namespace airseg
