#pragma once
// The autopilot's commands on the command dispatcher (local socket and ground link alike):
//   {"cmd":"state","state":"PARKING"}              control  → {"state":"PARKING"} once the autopilot confirms
//   {"cmd":"param.get","name":"WP_RADIUS"}         monitor  → {"name":"WP_RADIUS","value":2}
//   {"cmd":"param.set","name":"WP_RADIUS","value":3} control → {"name":"WP_RADIUS","value":3} (read back)
// Each becomes an AutopilotRequest on the bus; the reply waits for the RequestDone with the same id, so a
// command is never answered "ok" before the autopilot has confirmed it.
#include <cstdint>
#include <map>

#include "services/autopilot/autopilot.hpp"
#include "services/common/bus.hpp"
#include "services/common/command_dispatcher.hpp"

namespace airseg::daemon {

class AutopilotCommands {
  public:
    /// Requests carry ids from kFirstId up, apart from those of other requesters on the bus.
    static constexpr std::uint32_t kFirstId = 0x80000000u;

    AutopilotCommands(Bus& bus, CommandDispatcher& commands, Strand strand);

  private:
    struct Pending {
        Json result;  // what an ok reply carries, completed from the RequestDone
        CommandDispatcher::Reply reply;
    };
    void add_param_list(CommandDispatcher& commands);
    void request(autopilot::AutopilotRequest r, Json result, CommandDispatcher::Reply reply);
    void on_done(const autopilot::RequestDone& done);

    Bus& bus_;
    Strand strand_;
    std::uint32_t next_id_ = kFirstId;
    std::map<std::uint32_t, Pending> pending_;  // touched on strand_ only
    Subscription done_subscription_;
};

/// The command result for a finished request (ok carries `result`, anything else names why).
CommandResult command_result(const autopilot::RequestDone& done, Json result);

}  // namespace airseg::daemon
