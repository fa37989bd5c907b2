#pragma once
// The autopilot's commands on the command dispatcher (local socket and ground link alike):
//   {"cmd":"state","state":"PARKING"}              control  → {"state":"PARKING"} once the autopilot confirms
//   {"cmd":"param.get","name":"WP_RADIUS"}         monitor  → {"name":"WP_RADIUS","value":2}
//   {"cmd":"param.set","name":"WP_RADIUS","value":3} control → {"name":"WP_RADIUS","value":3} (read back)
// Each becomes an AutopilotRequest on the bus whose Reply answers the command, so a command is never answered
// "ok" before the autopilot has confirmed it, and is answered "failed" when no autopilot service takes it.
#include "services/autopilot/autopilot.hpp"
#include "services/common/bus.hpp"
#include "services/common/command_dispatcher.hpp"
#include "services/common/reply.hpp"

namespace airseg::daemon {

class AutopilotCommands {
  public:
    AutopilotCommands(Bus& bus, CommandDispatcher& commands, Strand strand);

  private:
    void add_param_list(CommandDispatcher& commands);
    using Op = decltype(autopilot::AutopilotRequest::op);
    void request(Op op, Json result, CommandDispatcher::Reply reply);

    Bus& bus_;
    Strand strand_;
    ReplyGuard guard_;  // a command answered after the daemon dropped its commands would reach a gone caller
};

/// The command result for a finished request (ok carries `result`, anything else names why).
CommandResult command_result(const autopilot::RequestDone& done, Json result);

}  // namespace airseg::daemon
