#pragma once
// A small simulated autopilot for WindowFeeder tests: mission slots (0 = home), a current target, reaches one
// target per step while in auto, follows JumpTo items, parks on Stop items and falls into HOLD when it passes
// the last slot (ArduPilot Rover behaviour at the end of a mission). Reboots lose the mission. Every mode
// change is reported, with its cause, as the autopilot driver reports it (mode_changes()).
//
// Two command processors, as ArduPilot Rover has had: AP_Mission (the default: the target is a copy taken
// when it became current; a rewritten waypoint leg restarts when the current navigation command or the next
// two change, counted in restarts(), while a Stop being driven to stays until a set-current) and APM:Rover
// 2.42-2.45 (`legacy`): once a place is reached the do-commands between it and the next place run, a JumpTo
// continues at its slot (and the do-commands after the place it lands on run at once, on the way to that
// place), a Stop ends the mission there (the driver writes it as a DO_JUMP past the end, after which the
// board holds by itself), and a do-command with no place after it never runs.
#include <algorithm>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "services/flightplan/window_feeder.hpp"

namespace airseg::flightplan::test {

using autopilot::MissionItem;
using autopilot::ModeChangeCause;
using autopilot::RequestResult;
using autopilot::VehicleState;

class SimAutopilot {
  public:
    SimAutopilot() { reboot(); }
    /// APM:Rover 2.42-2.45's command processor (see above).
    bool legacy = false;

    RequestResult apply(const FeederRequest& r) {
        if (const auto* up = std::get_if<autopilot::UploadMission>(&r.op)) {
            slots_.assign(1, home());
            for (const auto& item : up->items) {
                slots_.push_back(item);
            }
            if (current_ == 0 || current_ >= slots_.size()) {
                current_ = 1;
            }
            take_target();
            return RequestResult::Ok;
        }
        if (const auto* w = std::get_if<autopilot::WriteMissionItems>(&r.op)) {
            if (w->first_slot == 0 || w->first_slot + w->items.size() > slots_.size()) {
                return RequestResult::Timeout;
            }
            const auto watched = legacy ? std::vector<std::uint16_t>{} : look_ahead();
            bool watched_changed = false;
            for (std::size_t i = 0; i < w->items.size(); ++i) {
                const auto slot = static_cast<std::uint16_t>(w->first_slot + i);
                if (slots_[slot] != w->items[i] &&
                    std::find(watched.begin(), watched.end(), slot) != watched.end()) {
                    watched_changed = true;
                }
                slots_[slot] = w->items[i];
            }
            if (watched_changed && auto_ && target_.kind == MissionItem::Kind::Waypoint) {
                ++restarts_;  // "Auto mission changed, restarted command": the leg is planned afresh
                take_target();
            }
            ++writes_;
            return RequestResult::Ok;
        }
        if (const auto* s = std::get_if<autopilot::SetMissionCurrent>(&r.op)) {
            if (s->slot == 0 || s->slot >= slots_.size() || (legacy && !is_place(slots_[s->slot]))) {
                return RequestResult::Timeout;  // 2.x: "Bad Request - cannot change to non-Nav cmd"
            }
            current_ = s->slot;
            take_target();
            return RequestResult::Ok;
        }
        const auto& change = std::get<autopilot::RequestStateChange>(r.op);
        if (change.state == VehicleState::Parking) {
            set_mode(VehicleState::Parking, ModeChangeCause::Requested);
            ++hold_requests_;
            return RequestResult::Ok;
        }
        set_mode(VehicleState::WaypointNavigation, ModeChangeCause::Requested);
        return RequestResult::Ok;
    }

    struct ModeReport {
        VehicleState mode;
        ModeChangeCause cause;
    };
    /// Mode changes since the last call, oldest first.
    std::vector<ModeReport> mode_changes() { return std::exchange(changes_, {}); }

    /// Drives to the current target: returns the reached slot, if any.
    std::optional<std::uint16_t> step() {
        if (!auto_ || current_ == 0 || current_ >= slots_.size()) {
            return std::nullopt;
        }
        if (target_.kind != MissionItem::Kind::Waypoint) {
            parked_ = true;  // at a Stop: it stays there
            return std::nullopt;
        }
        visited_.push_back({target_.lat, target_.lon});
        const std::uint16_t reached = current_;
        if (legacy) {
            legacy_advance(reached);
            return reached;
        }
        std::size_t next = current_ + 1u;
        for (int guard = 0;
             next < slots_.size() && slots_[next].kind == MissionItem::Kind::JumpTo && guard < 8; ++guard) {
            next = slots_[next].jump_slot;
        }
        if (next >= slots_.size()) {
            end_of_mission();
        } else {
            current_ = static_cast<std::uint16_t>(next);
            take_target();
        }
        return reached;
    }

    void reboot() {
        slots_.assign(1, home());
        current_ = 0;
        auto_ = false;
        mode_ = VehicleState::Unknown;
        parked_ = false;
        target_ = home();
    }

    /// ArduPilot's own reboot, as the driver first sees it: the mission stays in the board's storage and AUTO
    /// starts it at slot 1; the boot shows as INITIALISING (configure_check), then the boot mode (MANUAL).
    /// (reboot() is the board as the feeder knows it once the reboot is declared: nothing it held counts.)
    void boot_keeping_mission() {
        current_ = slots_.size() > 1 ? 1 : 0;
        take_target();
        set_mode(VehicleState::ConfigureCheck, ModeChangeCause::External);
        set_mode(VehicleState::Manual, ModeChangeCause::External);
    }

    /// The RC pilot takes the vehicle out of AUTO (the transmitter's MANUAL switch).
    void operator_takes_over() { set_mode(VehicleState::Directed, ModeChangeCause::External); }
    /// The autopilot falls into HOLD by itself (a failsafe, a quirk of its mission logic).
    void board_holds() { set_mode(VehicleState::Parking, ModeChangeCause::External); }
    /// An operator's state command (through this daemon, not the feeder) parks the vehicle.
    void operator_parks() { set_mode(VehicleState::Parking, ModeChangeCause::Requested); }

    std::uint16_t current() const { return current_; }
    bool in_auto() const { return auto_; }
    bool parked() const { return parked_; }
    const std::vector<LatLon>& visited() const { return visited_; }
    /// The mission as stored, slot 0 (home) first.
    const std::vector<MissionItem>& slots() const { return slots_; }
    int end_of_mission_holds() const { return end_of_mission_holds_; }
    /// Times a legacy board ended its mission at a Stop (a barrier, or the plan's end) and held.
    int stop_holds() const { return stop_holds_; }
    int hold_requests() const { return hold_requests_; }
    int writes() const { return writes_; }
    /// Waypoint legs restarted because the current navigation command or the next two changed.
    int restarts() const { return restarts_; }

  private:
    static constexpr std::uint16_t kPastTheEnd = 254;
    static bool is_place(const MissionItem& m) { return m.kind == MissionItem::Kind::Waypoint; }

    void take_target() {
        target_ = current_ < slots_.size() ? slots_[current_] : home();
        parked_ = false;
    }

    /// AP_Mission's change detector: the current navigation command and the next two, through jumps.
    std::vector<std::uint16_t> look_ahead() const {
        std::vector<std::uint16_t> out;
        std::size_t i = current_;
        for (int guard = 0; out.size() < 3 && i > 0 && i < slots_.size() && guard < 16; ++guard) {
            if (slots_[i].kind == MissionItem::Kind::JumpTo) {
                i = slots_[i].jump_slot;
                continue;
            }
            out.push_back(static_cast<std::uint16_t>(i));
            ++i;
        }
        return out;
    }

    // process_next_command() once `from` is reached: the next place, and the do-commands before it.
    void legacy_advance(std::size_t from) {
        bool jumped = false;
        for (int guard = 0; guard < 8; ++guard) {
            std::size_t place = from + 1;
            while (place < slots_.size() && !is_place(slots_[place])) {
                ++place;
            }
            if (place >= slots_.size()) {
                end_of_mission();  // "No commands - setting HOLD"
                return;
            }
            std::optional<std::size_t> jump;
            for (std::size_t i = from + 1; i < place; ++i) {
                if (slots_[i].kind == MissionItem::Kind::Stop) {
                    hold_past_the_end();
                    return;
                }
                if (slots_[i].kind == MissionItem::Kind::JumpTo) {
                    jump = slots_[i].jump_slot;
                    break;
                }
            }
            if (!jump) {
                current_ = static_cast<std::uint16_t>(place);
                take_target();
                if (jumped) {
                    // After a jump the do-commands that follow the target's place run at once, on the way to
                    // it: process_non_nav_command() clears the WAIT_COMMAND that the jump's own
                    // process_next_command() had set (commands_process.pde), so the next call steps on.
                    for (std::size_t i = place + 1; i < slots_.size() && !is_place(slots_[i]); ++i) {
                        if (slots_[i].kind == MissionItem::Kind::Stop) {
                            hold_past_the_end();
                            return;
                        }
                    }
                }
                return;
            }
            from = *jump - 1;  // do_jump(): the processor carries on at the jump's target
            jumped = true;
        }
    }

    void hold_past_the_end() {
        ++stop_holds_;  // a DO_JUMP past the end: no commands left, HOLD where it is
        set_mode(VehicleState::Parking, ModeChangeCause::External);
        parked_ = true;
        current_ = kPastTheEnd;  // MISSION_CURRENT carries the jump's target, less one
    }

    void end_of_mission() {
        set_mode(VehicleState::Parking, ModeChangeCause::External);  // mission complete: Rover goes HOLD
        ++end_of_mission_holds_;
    }

    void set_mode(VehicleState mode, ModeChangeCause cause) {
        auto_ = mode == VehicleState::WaypointNavigation;
        if (mode != mode_) {
            mode_ = mode;
            changes_.push_back({mode, cause});
        }
    }
    static MissionItem home() { return MissionItem{}; }
    std::vector<MissionItem> slots_;
    std::uint16_t current_ = 0;
    MissionItem target_;
    bool auto_ = false;
    VehicleState mode_ = VehicleState::Unknown;
    std::vector<ModeReport> changes_;
    bool parked_ = false;
    std::vector<LatLon> visited_;
    int end_of_mission_holds_ = 0;
    int stop_holds_ = 0;
    int hold_requests_ = 0;
    int writes_ = 0;
    int restarts_ = 0;
};

/// A lazily generated straight-line plan of n waypoints; selected indices can carry hold actions.
class SyntheticStream final : public WaypointStream {
  public:
    explicit SyntheticStream(std::uint64_t n, double base_lat = 41.0,
                             std::map<std::uint64_t, Waypoint> overrides = {})
        : n_(n), base_lat_(base_lat), overrides_(std::move(overrides)) {}

    static LatLon position_of(double base_lat, std::uint64_t i) {
        return {base_lat + static_cast<double>(i) * 1e-4, 2.0 + static_cast<double>(i % 7) * 1e-5};
    }

    std::optional<Waypoint> next() override {
        if (pos_ >= n_) {
            return std::nullopt;
        }
        Waypoint w;
        if (auto it = overrides_.find(pos_); it != overrides_.end()) {
            w = it->second;
        }
        w.index = pos_;
        w.element = 0;
        if (w.has_position) {
            w.position = position_of(base_lat_, pos_);
        }
        w.speed = 2.0;
        w.arrival_radius = 2.0;
        w.first_of_element = pos_ == 0;
        w.last_of_element = pos_ + 1 == n_;
        ++pos_;
        return w;
    }
    bool seek(std::uint64_t index) override {
        if (index >= n_) {
            return false;
        }
        pos_ = index;
        return true;
    }
    bool jump_to(std::string_view name) override {
        if (name != "second-half") {
            return false;
        }
        pos_ = n_ / 2;
        return true;
    }
    std::string element_path(std::uint32_t) const override { return "plan.elements[0]"; }
    std::optional<std::string> error() const override { return std::nullopt; }

  private:
    std::uint64_t n_;
    double base_lat_;
    std::map<std::uint64_t, Waypoint> overrides_;
    std::uint64_t pos_ = 0;
};

struct Impairments {
    double duplicate_reached = 0.0;  // probability a reached report is delivered twice
    double delay_reached = 0.0;      // probability a reached report arrives one step late
    double drop_reached = 0.0;       // probability a reached report is lost
    double fail_request = 0.0;       // probability a request fails
    bool fail_writes = false;        // every partial write fails (the autopilot refuses them)
    bool refuse_missions = false;    // every upload and write is refused (a board that takes none of them)
    int requests_per_step = 2;       // link budget
    bool report_current = true;      // MISSION_CURRENT every step
    bool current_on_change =
        false;  // ... only when it changed, as the driver tells it (MissionCurrentChanged)
    // The feeder's own stalls (a starved daemon): at each step a stall starts with this probability and lasts
    // 1..stall_steps steps, during which the vehicle drives on and its reports wait in the port.
    double stall = 0.0;
    int stall_steps = 6;
    bool fail_next_set_current = false;  // the next set-current times out (one-shot)
};

/// Drives a feeder against the simulated autopilot in simulated time, one second per step.
class Harness {
  public:
    explicit Harness(FeederConfig config = {}, Impairments imp = {}, unsigned seed = 1)
        : feeder(config), imp_(imp), rng_(seed) {}

    void step() {
        if (stall_left_ == 0 && chance(imp_.stall)) {
            stall_left_ = std::uniform_int_distribution<int>(1, imp_.stall_steps)(rng_);
            ++stalls;
        }
        if (stall_left_ > 0) {
            --stall_left_;
            if (const auto reached = ap.step()) {
                waiting_.push_back(*reached);  // read from the port once the daemon runs again
            }
            now += seconds(1);
            return;
        }
        report_modes();  // what the vehicle did between steps (the RC pilot, the board itself)
        if (!waiting_.empty()) {
            // Back from a stall: what the port holds is read before anything is decided.
            for (auto s : std::exchange(waiting_, {})) {
                feeder.on_reached(s, now);
                drain();
            }
            feeder.on_current(ap.current(), now);
            drain();
        }
        int budget = imp_.requests_per_step;
        while (budget-- > 0) {
            auto r = feeder.poll_request(now);
            if (!r) {
                break;
            }
            const bool set_current = std::holds_alternative<autopilot::SetMissionCurrent>(r->op);
            const bool fail =
                (set_current && std::exchange(imp_.fail_next_set_current, false)) ||
                chance(imp_.fail_request) ||
                (imp_.fail_writes && std::holds_alternative<autopilot::WriteMissionItems>(r->op));
            const bool refuse =
                imp_.refuse_missions && (std::holds_alternative<autopilot::WriteMissionItems>(r->op) ||
                                         std::holds_alternative<autopilot::UploadMission>(r->op));
            const RequestResult res = refuse ? RequestResult::Refused
                                      : fail ? RequestResult::Timeout
                                             : ap.apply(*r);
            // The driver reports a confirmed mode change before the request's result, and with a write's
            // result how the board runs a Stop: a 2.x board (legacy) as the end of its mission.
            report_modes();
            if (std::holds_alternative<autopilot::WriteMissionItems>(r->op) ||
                std::holds_alternative<autopilot::UploadMission>(r->op)) {
                feeder.set_stop_ends_mission(ap.legacy);
            }
            feeder.on_request_result(r->id, res, now, refuse ? "MAV_MISSION_UNSUPPORTED_FRAME" : "");
            drain();
        }
        std::vector<std::uint16_t> deliver(late_.begin(), late_.end());
        late_.clear();
        const auto reached_now = ap.step();
        report_modes();
        if (auto reached = reached_now) {
            if (chance(imp_.drop_reached)) {
                // lost
            } else if (chance(imp_.delay_reached)) {
                late_.push_back(*reached);
            } else {
                deliver.insert(deliver.begin(), *reached);
                if (chance(imp_.duplicate_reached)) {
                    deliver.push_back(*reached);
                }
            }
        }
        for (auto s : deliver) {
            feeder.on_reached(s, now);
            drain();
        }
        if (imp_.report_current && (!imp_.current_on_change || ap.current() != last_current_)) {
            last_current_ = ap.current();
            feeder.on_current(ap.current(), now);
            drain();
        }
        now += seconds(1);
        if (feeder.poll_timeout() <= now) {
            feeder.handle_timeout(now);
        }
        drain();
    }

    /// Steps until the vehicle is in AUTO (or the limit); returns the steps taken.
    int run_until_auto(int limit) {
        int steps = 0;
        while (!ap.in_auto() && steps < limit) {
            step();
            ++steps;
        }
        return steps;
    }

    /// Steps until the plan is done (or the limit); returns the steps taken.
    int run_until_done(int limit) {
        for (int i = 0; i < limit; ++i) {
            if (feeder.progress().state == PlanState::Done) {
                return i;
            }
            step();
        }
        return limit;
    }

    void report_modes() {
        for (const auto& m : ap.mode_changes()) {
            feeder.on_mode(m.mode, m.cause, now);
            drain();
        }
    }

    void drain() {
        while (auto e = feeder.poll_event()) {
            if (e->kind == FeederEvent::Kind::WaypointReached) {
                reached.push_back(e->plan_index);
            }
            events.push_back(*e);
        }
    }

    std::size_t count(FeederEvent::Kind kind) const {
        std::size_t n = 0;
        for (const auto& e : events) {
            n += e.kind == kind;
        }
        return n;
    }

    Impairments& impairments() { return imp_; }
    /// The feeder is stalled, or has not yet read what came meanwhile (nothing reaches a stopped daemon).
    bool stalled() const { return stall_left_ > 0 || !waiting_.empty(); }

    WindowFeeder feeder;
    SimAutopilot ap;
    TimePoint now{};
    int stalls = 0;
    std::vector<std::uint64_t> reached;
    std::vector<FeederEvent> events;

  private:
    bool chance(double p) { return p > 0.0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < p; }
    Impairments imp_;
    std::mt19937 rng_;
    std::deque<std::uint16_t> late_;
    std::deque<std::uint16_t> waiting_;
    int stall_left_ = 0;
    std::uint16_t last_current_ = 0xffff;  // what the feeder was last told the target is
};

inline PlanFeed synthetic(std::uint64_t n, double base_lat = 41.0,
                          std::map<std::uint64_t, Waypoint> overrides = {}) {
    return PlanFeed{std::make_unique<SyntheticStream>(n, base_lat, std::move(overrides)), "synthetic"};
}

}  // namespace airseg::flightplan::test
