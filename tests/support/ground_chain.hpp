#pragma once
// One simulated vehicle and its ground hub on real ptys: airseg-apmsim ⇄ airsegd ⇄ airseg-linksim (57600
// baud) ⇄ airseg-ground, every process logging into one directory. The ground station tests start one or
// several.
#include <memory>
#include <string>
#include <vector>

#include "tests/support/process.hpp"

namespace airseg::test {

class GroundChain {
  public:
    static constexpr double kHomeLat = 41.2756;
    static constexpr double kHomeLon = 1.9866;

    /// Processes log into `dir` (created if missing); `hub_args` go to airseg-ground after the radio, key and
    /// socket.
    GroundChain(std::string dir, std::vector<std::string> hub_args);
    ~GroundChain();  // stops the hub and the daemon gently, so their logs end cleanly
    GroundChain(const GroundChain&) = delete;
    GroundChain& operator=(const GroundChain&) = delete;

    /// Starts the processes and waits until the vehicle answers through the hub with its autopilot ready;
    /// what went wrong (with the logs), empty when it is up.
    std::string start();

    std::string file(const std::string& name) const { return dir_ + "/" + name; }
    const std::string& dir() const { return dir_; }
    std::string socket() const { return file("ground.sock"); }
    const std::string& key() const { return key_; }

    /// airsegctl through the hub's socket, with --json and, when `with_key`, the control key.
    std::vector<std::string> ctl_argv(std::vector<std::string> args, bool with_key) const;
    RunResult ctl(std::vector<std::string> args, bool with_key = false) const;

    std::unique_ptr<Subprocess> linksim, sim, daemon, hub;

  private:
    std::string dir_;
    std::vector<std::string> hub_args_;
    std::string key_;
};

}  // namespace airseg::test
