#pragma once
// LimitedLog: spdlog behind a LineLimiter per kind of line (base/line_limiter.hpp). Every log line a peer can
// trigger (a client, the radio, the autopilot, a ground station) goes through one, so a flood costs at most
// `burst` lines per kind and period plus one summary:
//   autopilot[/dev/ttyACM0]: autopilot rebooted … repeated 12,000 more times in 10 s (not logged)
// Kinds are fixed texts chosen by the code (never text from the peer), so the table stays as small as the
// code that logs. Use it from one strand; held_everywhere() is the process-wide count status shows.
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>

#include "base/line_limiter.hpp"

namespace airseg {

class LimitedLog {
  public:
    using Level = spdlog::level::level_enum;

    explicit LimitedLog(LineLimiterConfig config = {}) : config_(config) {}

    template <typename... Args>
    void log(std::string_view kind, TimePoint now, Level level, fmt::format_string<Args...> format,
             Args&&... args) {
        // A view, not a std::string: a kind is a literal. With a temporary string per call in each case label
        // of a switch, clang 14 (-O1, ASan) ran a string destructor out of its scope on leaving the switch
        // (GroundlinkService::on_event: stack-use-after-scope at the first link event).
        auto it = kinds_.find(kind);
        if (it == kinds_.end()) {
            it = kinds_.try_emplace(std::string(kind), config_).first;
        }
        Kind& k = it->second;
        const auto verdict = k.limiter.admit(now);
        if (verdict.held > 0) {
            summarise(kind, k, verdict.held);
        }
        if (verdict.pass) {
            k.level = level;
            spdlog::log(level, format, std::forward<Args>(args)...);
        } else {
            held_everywhere_counter().fetch_add(1, std::memory_order_relaxed);
        }
    }

    /// Summaries for kinds whose flood has stopped: call it now and then (a service's progress tick).
    void flush(TimePoint now) {
        for (auto& [kind, k] : kinds_) {
            if (const auto held = k.limiter.poll_held(now)) {
                summarise(kind, k, *held);
            }
        }
    }

    /// Lines this log held back.
    std::uint64_t held_total() const {
        std::uint64_t total = 0;
        for (const auto& [kind, k] : kinds_) {
            total += k.limiter.held_total();
        }
        return total;
    }

    /// Lines held back by every LimitedLog of the process.
    static std::uint64_t held_everywhere() {
        return held_everywhere_counter().load(std::memory_order_relaxed);
    }

    /// 12000 -> "12,000".
    static std::string thousands(std::uint64_t n) {
        const std::string digits = std::to_string(n);
        std::string out;
        out.reserve(digits.size() + digits.size() / 3);
        for (std::size_t i = 0; i < digits.size(); ++i) {
            if (i > 0 && (digits.size() - i) % 3 == 0) {
                out += ',';
            }
            out += digits[i];
        }
        return out;
    }

  private:
    struct Kind {
        explicit Kind(LineLimiterConfig config) : limiter(config) {}
        LineLimiter limiter;
        Level level = Level::info;
    };

    void summarise(std::string_view kind, const Kind& k, std::uint64_t held) const {
        const auto period_s = std::chrono::duration_cast<std::chrono::seconds>(k.limiter.period()).count();
        spdlog::log(k.level, "{} … repeated {} more times in {} s (not logged)", kind, thousands(held),
                    period_s);
    }

    static std::atomic<std::uint64_t>& held_everywhere_counter() {
        static std::atomic<std::uint64_t> counter{0};
        return counter;
    }

    LineLimiterConfig config_;
    std::map<std::string, Kind, std::less<>> kinds_;
};

}  // namespace airseg
