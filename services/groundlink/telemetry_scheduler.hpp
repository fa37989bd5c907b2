#pragma once
// The telemetry scheduler: decides when each kind of pushed telemetry goes to the ground.
//
// Contract (sans-IO): the caller passes `now` to every call and never lets it go backwards.
//   inputs   set_config (configuration, SIGHUP), set_rate (from the ground), update_link (once per link
//            statistics tick: the transport's measured loss and how many Fast messages it had to replace)
//   outputs  poll_due(now) (one kind due now, or nothing; call until nothing), poll_timeout() (the earliest
//            next deadline), poll_slack() (how late polling may be), effective_hz / factor / budget figures
//            for the status document.
//
// Effective rate of a kind = requested rate × budget scale × weak-link factor, never below min_hz (unless the
// kind is off). The budget scale keeps the pushed telemetry within budget_share of the link rate. The
// weak-link factor halves (down to 1/8) while the link stays weak and doubles back once it has stayed good.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/time.hpp"

namespace airseg::groundlink {

enum class TelemetryKind : std::uint8_t { Vehicle, LinkStats };
inline constexpr std::size_t kTelemetryKinds = 2;
inline constexpr std::array<TelemetryKind, kTelemetryKinds> kAllTelemetryKinds{TelemetryKind::Vehicle,
                                                                               TelemetryKind::LinkStats};
const char* to_string(TelemetryKind kind);  // "vehicle", "link_stats"
std::optional<TelemetryKind> telemetry_kind_from_string(std::string_view name);

struct TelemetrySchedulerConfig {
    static constexpr double kMaxHz = 20.0;
    /// groundlink.telemetry.rates: requested rate per kind, Hz (0 = off).
    std::array<double, kTelemetryKinds> rate_hz{2.0, 1.0};
    /// Bytes one message of each kind costs on the wire, transport framing included.
    std::array<double, kTelemetryKinds> wire_bytes{48.0, 37.0};
    /// groundlink.telemetry.budget_share: fraction of the link rate pushed telemetry may use.
    double budget_share = 0.25;
    /// groundlink.telemetry.min_hz: floor of a kind that is on, whatever the budget and the link.
    double min_hz = 0.2;
    /// groundlink.telemetry.weak_loss / good_loss: frame loss (or share of telemetry messages replaced
    /// before they could be sent) above which the link is weak, below which it is good again.
    double weak_loss = 0.15;
    double good_loss = 0.05;
    /// How long the link must stay weak before each halving, and good before each doubling.
    Duration weak_after = std::chrono::seconds(2);
    Duration recover_after = std::chrono::seconds(10);
    /// Lowest weak-link factor.
    double min_factor = 0.125;

    /// Every problem, each naming its key; empty when usable.
    [[nodiscard]] std::vector<std::string> validate() const;
};

/// What the transport measured over the last statistics interval.
struct LinkQuality {
    bool up = false;
    double loss = 0.0;            // fraction of frames lost (transport estimate)
    double replaced_share = 0.0;  // fraction of Fast messages replaced in the queue before going out
    double link_rate_bytes_per_s = 0.0;
};

class TelemetryScheduler {
  public:
    TelemetryScheduler(TelemetrySchedulerConfig config, double link_rate_bytes_per_s, TimePoint now);

    /// A new configuration (SIGHUP): requested rates from it replace those set from the ground.
    void set_config(const TelemetrySchedulerConfig& config, TimePoint now);
    /// A rate requested from the ground; returns an error for people when out of range.
    std::optional<std::string> set_rate(TelemetryKind kind, double hz, TimePoint now);
    void update_link(const LinkQuality& quality, TimePoint now);

    /// One kind whose message is due now (its next deadline moves on), or nothing.
    std::optional<TelemetryKind> poll_due(TimePoint now);
    [[nodiscard]] TimePoint poll_timeout() const;
    /// How late a poll may come without costing a kind its rate: half the shortest period of the kinds on
    /// (zero when all are off). A late poll lands on the next grid point, so the rates hold.
    [[nodiscard]] Duration poll_slack() const;

    [[nodiscard]] double requested_hz(TelemetryKind kind) const;
    [[nodiscard]] double effective_hz(TelemetryKind kind) const;
    [[nodiscard]] double factor() const { return factor_; }
    [[nodiscard]] double budget_bytes_per_s() const { return budget_; }
    [[nodiscard]] bool weak() const { return weak_; }
    [[nodiscard]] std::uint64_t lowerings() const { return lowerings_; }
    [[nodiscard]] std::uint64_t restorations() const { return restorations_; }
    [[nodiscard]] const TelemetrySchedulerConfig& config() const { return config_; }

  private:
    void recompute(TimePoint now);

    TelemetrySchedulerConfig config_;
    double link_rate_;
    double budget_ = 0;
    double factor_ = 1.0;
    bool weak_ = false;
    TimePoint weak_since_ = kNever;
    TimePoint good_since_ = kNever;
    TimePoint last_change_;
    std::array<double, kTelemetryKinds> requested_{};
    std::array<double, kTelemetryKinds> effective_{};
    std::array<TimePoint, kTelemetryKinds> next_due_{};
    std::uint64_t lowerings_ = 0;
    std::uint64_t restorations_ = 0;
};

}  // namespace airseg::groundlink
