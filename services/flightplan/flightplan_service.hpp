#pragma once
// FlightplanService: the asio side of the flight plan manager. The decisions are the sans-IO PlanController's
// (driving the WindowFeeder, reactions, commands waiting for the autopilot, status); this adapter feeds it
// the bus messages and commands, carries its requests, events and status to the bus, answers the commands,
// keeps plan and progress in the state directory (StateStore) and resumes them at start.
//
// Commands (command dispatcher; see docs/flight-plan.md): plan.load, plan.append, plan.show, plan.geometry,
// plan.skip, plan.pause, plan.resume. A command that changes the vehicle is answered once the autopilot has
// confirmed everything it required (the feeder has nothing left to ask), or with the failure.
//
// Bus: subscribes autopilot::AutopilotStatus, Telemetry, WaypointReached, MissionCurrentChanged, ModeChanged,
// AutopilotRebooted, GroundStationMission (answered through its Reply), groundlink::LinkState (the ground
// link's up/down state, a typed variable); publishes
// AutopilotRequest (answered through its Reply), FeederEvent and ReactionTrigger (events) and the "plan"
// status section.
// Log prefix: flightplan: .
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "services/common/deadline_timer.hpp"
#include "services/common/limited_log.hpp"
#include "services/common/service.hpp"
#include "services/common/slack_timer.hpp"
#include "services/flightplan/persistence.hpp"
#include "services/flightplan/plan_controller.hpp"

namespace airseg::flightplan {

struct FlightplanServiceConfig {
    FeederConfig feeder;
    LoadOptions load;
    std::string state_dir;  // state_dir: plan.yaml and progress.state; empty = nothing kept
    Durability durability = Durability::Fsync;    // flightplan.fsync
    Duration command_timeout = seconds(30);       // how long a command waits for the autopilot
    Duration status_period = milliseconds(1000);  // the "plan" section is checked for changes this often
};

class FlightplanService : public Service {
  public:
    FlightplanService(ServiceContext& ctx, FlightplanServiceConfig config);
    ~FlightplanService() override;

  protected:
    void on_start() override;
    void on_stop() override;
    void on_tick(TimePoint now) override;

  private:
    /// What every log line of this service starts with.
    static constexpr const char* kPrefix = "flightplan: ";

    // commands (flightplan_commands.cpp)
    void register_commands();
    void cmd_load(const Json& req, CommandDispatcher::Reply reply, bool append);
    void cmd_skip(const Json& req, CommandDispatcher::Reply reply);
    void cmd_geometry(const Json& req, CommandDispatcher::Reply reply);
    CommandId keep_reply(CommandDispatcher::Reply reply);
    /// A ground station's mission: loaded as plan.load would load it, or refused while a plan runs.
    void on_ground_station_mission(const autopilot::GroundStationMission& m);

    /// Carries out what the controller decided after an input: bus, replies, state store, logs, timer.
    void flush();
    void publish_status(bool force);
    /// Sends the request with a Reply that hands the answer to the controller.
    void call(AutopilotCall c);
    void schedule_status();

    FlightplanServiceConfig config_;
    std::optional<StateStore> store_;
    PlanController controller_;
    std::map<CommandId, CommandDispatcher::Reply> replies_;
    CommandId next_command_id_ = 1;

    DeadlineTimer timer_;
    SlackTimer status_timer_;
    std::vector<Subscription> subscriptions_;
    std::optional<ReplyGuard> calls_;  // the autopilot's answers run only while started
    bool running_ = false;
    // The plan's events follow the autopilot's (reached, interrupted, reactions) and ground stations'
    // uploads: a peer that floods them gets a burst per period, one limiter per level.
    LimitedLog log_{LineLimiterConfig{20, seconds(10)}};
};

}  // namespace airseg::flightplan
