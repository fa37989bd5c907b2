#pragma once
// PlanController: the flight plan manager's decisions, sans-IO. It drives the WindowFeeder against the
// autopilot, carries out the plan's reactions (ReactionMonitor), answers the commands that wait for the
// autopilot, decides what a reconnected or rebooted autopilot needs and what progress is worth keeping.
//
// Contract: inputs are method calls with the time (autopilot events and telemetry in the autopilot-neutral
// vocabulary, the ground link's state, commands already parsed); call handle_timeout(now) when
// poll_timeout() is due. After every call, drain the outputs: poll_output (requests for the autopilot and
// events to publish, in the order they are to go out), poll_reply (answers to commands, exactly one per
// command id), poll_save (progress to keep; report the outcome with on_saved), poll_status and poll_log.
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <variant>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/flightplan/expander.hpp"
#include "services/flightplan/persistence.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/plan_progress.hpp"
#include "services/flightplan/reaction_monitor.hpp"
#include "services/flightplan/resume.hpp"
#include "services/flightplan/window_feeder.hpp"

namespace airseg::flightplan {

using Json = nlohmann::json;

struct PlanControllerConfig {
    FeederConfig feeder;
    LoadOptions load;
    bool keeps_progress = false;             // a state store is there: progress comes out through poll_save
    Duration command_timeout = seconds(30);  // how long a command waits for the autopilot
};

/// A plan as it runs: the loaded plan, its text (kept for plan.append and persistence) and its stream.
struct ActivePlan {
    std::shared_ptr<const Plan> plan;
    std::string text;
    std::string source;
    std::string digest;
    Expander* stream = nullptr;  // owned by the feeder; null while returning home
};

using CommandId = std::uint64_t;

struct CommandReply {
    enum class Status : std::uint8_t { Ok, Refused, BadRequest, Failed };
    CommandId id = 0;
    Status status = Status::Ok;
    Json result = Json::object();  // when ok
    std::string error;             // when not
};

struct ProgressSave {
    SavedProgress progress;
    bool report_failure = true;  // a failure becomes plan.error
};

struct StatusUpdate {
    PlanProgress progress;        // the latest value, every time
    std::optional<Json> section;  // the "plan" status section, when it changed (or was forced)
};

struct LogLine {
    enum class Level : std::uint8_t { Debug, Info, Warn, Error };
    Level level = Level::Info;
    std::string text;  // without the service's prefix
};

/// A request for the autopilot; its answer comes back through on_request_done() with the same id.
struct AutopilotCall {
    std::uint32_t id = 0;
    autopilot::AutopilotRequest request;
};

/// What goes out on the bus: a request for the autopilot, or an event.
using PlanOutput = std::variant<AutopilotCall, FeederEvent, ReactionTrigger>;

/// A plan.load / plan.append request, read but not yet checked against the running plan.
struct LoadRequest {
    std::string text;
    std::string source;
    bool append = false;
};

class PlanController {
  public:
    explicit PlanController(PlanControllerConfig config);

    // ---- life cycle
    void start(TimePoint now);
    /// Fails the waiting commands; nothing is decided afterwards.
    void stop(const std::string& why);
    /// Takes over what the state store kept (resume_from's result).
    void resume(ResumeResult result, TimePoint now);

    // ---- autopilot
    void on_autopilot_status(const autopilot::AutopilotStatus& s, TimePoint now);
    void on_telemetry(const autopilot::Telemetry& t, TimePoint now);
    void on_reached(std::uint32_t seq, TimePoint now);
    void on_current(std::uint32_t seq, TimePoint now);
    void on_item_stored(std::uint16_t slot, const autopilot::MissionItem& item, TimePoint now);
    void on_rebooted(TimePoint now);
    void on_mode_changed(const autopilot::ModeChanged& m, TimePoint now);
    /// The answer to the AutopilotCall with this id (its RequestDone::id is the autopilot's own).
    void on_request_done(std::uint32_t id, const autopilot::RequestDone& done, TimePoint now);

    // ---- ground link
    void on_link(bool up, TimePoint now);

    // ---- commands
    /// Checks a load or append against the running plan: the plan to start, or the command's failure
    /// (answered to `id`, nothing changed).
    std::optional<ActivePlan> prepare_load(CommandId id, LoadRequest request);
    /// Starts a prepared plan (`from`: the text the command brought); answered once the autopilot has
    /// confirmed it.
    void load(CommandId id, ActivePlan plan, bool append, bool start_paused, const std::string& from,
              TimePoint now);
    /// plan.skip to a waypoint index or a named element.
    void skip(CommandId id, std::variant<std::uint64_t, std::string> target, TimePoint now);
    void pause(CommandId id, TimePoint now);
    void resume_plan(CommandId id, TimePoint now);
    Json show() const;
    /// The running plan's shape for a map (plan.geometry): every positioned element once, in plan order
    /// (a repeat's body once, detached blocks after the main list), and the no-fly zones. At most
    /// `max_points` points in all; "truncated" says when some were left out.
    Json geometry(std::size_t max_points) const;

    // ---- persistence
    void on_saved(const ProgressSave& save, const std::optional<std::string>& error);

    // ---- time
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;
    /// The periodic republication of the status section.
    void publish_status(bool force);

    // ---- outputs
    std::optional<PlanOutput> poll_output();
    std::optional<CommandReply> poll_reply();
    std::optional<ProgressSave> poll_save();
    std::optional<StatusUpdate> poll_status();
    std::optional<LogLine> poll_log();

    // ---- state, for the adapter and tests
    const std::optional<ActivePlan>& active() const { return active_; }
    bool returning_home() const { return returning_home_; }
    FeederProgress progress() const { return feeder_.progress(); }
    Json progress_json() const;
    // What progress_json() shows, as plain values: compared at every status check, where building the JSON
    // to compare would cost about 10,000 instructions.
    using StatusKey = std::tuple<PlanState, std::string, std::string, std::uint64_t,
                                 std::optional<std::uint64_t>, std::size_t, std::string, std::string,
                                 std::string, bool, std::uint64_t, Duration, std::string, bool>;
    StatusKey status_key(const FeederProgress& p) const;
    /// plan.interruption: the feeder's last interruption, none once the plan is done.
    static const std::string& shown_interruption(const FeederProgress& p);

  private:
    struct Waiter {
        CommandId id = 0;
        std::string what;  // "plan.load", for messages
        TimePoint deadline;
    };
    struct InFlight {
        std::uint32_t feeder_id = 0;
        TimePoint sent{};
    };

    void start_plan(ActivePlan plan, bool append, TimePoint now);
    void save_progress();
    void carry_out(const ReactionTrigger& trigger, TimePoint now);
    bool return_home(TimePoint now);
    void tell_reactions_the_link(TimePoint now);
    void tell_reactions_the_telemetry(TimePoint now);
    void send(const FeederRequest& request, TimePoint now);
    void pump(TimePoint now);
    void handle_event(const FeederEvent& e);
    void wait_for_autopilot(CommandId id, std::string what, TimePoint now);
    void answer_waiters(TimePoint now);
    void fail_waiters(const std::string& why);
    void answer_waiters_without_autopilot(const std::string& why);
    void reply(CommandId id, CommandReply::Status status, std::string error, Json result = Json::object());
    void log(LogLine::Level level, std::string text);

    PlanControllerConfig config_;
    WindowFeeder feeder_;
    std::optional<ActivePlan> active_;
    std::unique_ptr<ReactionMonitor> reactions_;
    bool returning_home_ = false;
    bool running_ = false;

    bool autopilot_ready_ = false;
    // The autopilot's reconnects and reboots when it was last ready: back with the same counts, it only went
    // silent for a while (heartbeats lost) and still holds the window it was driving.
    std::optional<std::pair<unsigned, unsigned>> ready_counts_;
    std::optional<autopilot::Position> autopilot_home_;
    std::optional<int> last_battery_;  // the telemetry's, for a new plan's reactions
    std::optional<LatLon> last_position_;
    bool groundlink_seen_up_ = false;
    bool groundlink_up_ = false;
    std::map<std::uint32_t, InFlight> in_flight_;  // by AutopilotCall id
    std::uint32_t next_call_id_ = 1;
    std::optional<std::string> fault_;  // the last request failure, while the feeder is faulted
    std::string last_failure_;
    std::vector<Waiter> waiters_;

    // last_saved_: the point last handed out to be saved (not handed out again); last_written_: the last one
    // the store confirmed, which a way home keeps as paused even when later saves failed.
    std::optional<SavedProgress> last_saved_;
    std::optional<SavedProgress> last_written_;
    std::string problem_;        // plan.error: the last problem found (corrupt state, failed save, ...)
    std::string last_reaction_;  // plan.reaction
    std::optional<StatusKey> last_status_;

    std::deque<PlanOutput> outputs_;
    std::deque<CommandReply> replies_;
    std::deque<ProgressSave> saves_;
    std::deque<StatusUpdate> statuses_;
    std::deque<LogLine> logs_;
};

}  // namespace airseg::flightplan
