#pragma once
// FlightplanService: the asio side of the flight plan manager. It drives the sans-IO WindowFeeder against
// the autopilot through the autopilot-neutral bus requests (upload, partial write, set current, state
// change), feeds it the autopilot's reached / current / reboot events, carries out the plan's reactions
// (ReactionMonitor), keeps plan and progress in the state directory (StateStore) and resumes them at start.
//
// Commands (command dispatcher; see docs/flight-plan.md): plan.load, plan.append, plan.show, plan.skip,
// plan.pause, plan.resume. A command that changes the vehicle is answered once the autopilot has confirmed
// everything it required (the feeder has nothing left to ask), or with the failure.
//
// Bus: subscribes autopilot::AutopilotStatus, Telemetry, WaypointReached, MissionCurrentChanged, ModeChanged,
// AutopilotRebooted, RequestDone, status::StatusSection ("groundlink": the ground link's up/down state);
// publishes AutopilotRequest, FeederEvent and ReactionTrigger (events) and the "plan" status section.
// Log prefix: flightplan: .
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "services/autopilot/autopilot.hpp"
#include "services/common/deadline_timer.hpp"
#include "services/common/service.hpp"
#include "services/flightplan/expander.hpp"
#include "services/flightplan/persistence.hpp"
#include "services/flightplan/plan_loader.hpp"
#include "services/flightplan/reaction_monitor.hpp"
#include "services/flightplan/window_feeder.hpp"

namespace airseg::flightplan {

struct FlightplanServiceConfig {
    FeederConfig feeder;
    LoadOptions load;
    std::string state_dir;  // state_dir: plan.yaml and progress.state; empty = nothing kept
    Durability durability = Durability::Fsync;    // flightplan.fsync
    Duration command_timeout = seconds(30);       // how long a command waits for the autopilot
    Duration status_period = milliseconds(1000);  // the "plan" section is republished at least this often
};

class FlightplanService : public Service {
  public:
    /// Bus request ids of this service start here (apart from other requesters').
    static constexpr std::uint32_t kFirstRequestId = 0x40000000u;

    FlightplanService(ServiceContext& ctx, FlightplanServiceConfig config);
    ~FlightplanService() override;

  protected:
    void on_start() override;
    void on_stop() override;

  private:
    /// What every log line of this service starts with.
    static constexpr const char* kPrefix = "flightplan: ";
    struct ActivePlan {
        std::shared_ptr<const Plan> plan;
        std::string text;
        std::string source;
        std::string digest;
        Expander* stream = nullptr;  // owned by the feeder; null while returning home
    };
    struct Waiter {
        CommandDispatcher::Reply reply;
        std::string what;  // "plan.load", for messages
        TimePoint deadline;
    };

    // commands (flightplan_commands.cpp)
    void register_commands();
    void cmd_load(const Json& req, CommandDispatcher::Reply reply, bool append);
    void cmd_show(CommandDispatcher::Reply reply);
    void cmd_skip(const Json& req, CommandDispatcher::Reply reply);
    void cmd_pause(CommandDispatcher::Reply reply);
    void cmd_resume(CommandDispatcher::Reply reply);
    void wait_for_autopilot(std::string what, CommandDispatcher::Reply reply);
    Json progress_json() const;

    // plan handling
    std::optional<std::string> store_plan(const ActivePlan& plan);
    void start_plan(ActivePlan plan, bool append, TimePoint now);
    void resume_stored_plan(TimePoint now);
    void save_progress();
    void carry_out(const ReactionTrigger& trigger, TimePoint now);
    bool return_home(TimePoint now);

    // autopilot side
    void on_autopilot_status(const autopilot::AutopilotStatus& s);
    void on_request_done(const autopilot::RequestDone& done);
    void on_mode_changed(const autopilot::ModeChanged& m);
    void send(const FeederRequest& request);
    void pump();
    void handle_event(const FeederEvent& e);
    void answer_waiters(TimePoint now);
    void fail_waiters(const std::string& why);
    void arm_timer();
    void publish_status(bool force);
    void schedule_status();

    FlightplanServiceConfig config_;
    std::optional<StateStore> store_;
    WindowFeeder feeder_;
    std::optional<ActivePlan> active_;
    std::unique_ptr<ReactionMonitor> reactions_;
    bool returning_home_ = false;

    bool autopilot_ready_ = false;
    // The autopilot's reconnects and reboots when it was last ready: back with the same counts, it only went
    // silent for a while (heartbeats lost) and still holds the window it was driving.
    std::optional<std::pair<unsigned, unsigned>> ready_counts_;
    std::optional<autopilot::Position> autopilot_home_;
    bool groundlink_seen_up_ = false;
    bool groundlink_up_ = false;
    void tell_reactions_the_link(
        TimePoint now);  // the link's state as last published (LinkState, sent on changes only)
    struct InFlight {
        std::uint32_t feeder_id = 0;
        TimePoint sent{};
    };
    std::map<std::uint32_t, InFlight> in_flight_;  // by bus request id
    std::uint32_t next_bus_id_ = kFirstRequestId;
    std::optional<std::string> fault_;  // the last request failure, while the feeder is faulted
    std::string last_failure_;
    std::vector<Waiter> waiters_;

    std::optional<SavedProgress> last_saved_;
    std::string problem_;        // plan.error: the last problem found (corrupt state, failed save, ...)
    std::string last_reaction_;  // plan.reaction
    Json last_status_;

    DeadlineTimer timer_;
    asio::steady_timer status_timer_;
    std::vector<Subscription> subscriptions_;
    bool running_ = false;
};

}  // namespace airseg::flightplan
