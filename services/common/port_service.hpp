#pragma once
// A service whose job, until a protocol runs on top, is to hold its serial devices: it is UP while every
// device is open and DOWN (with the reason, e.g. "no /dev/ttyACM0") while one is missing, retrying each with
// backoff. The autopilot and ground-link services build on the same PortKeeper.
#include <memory>
#include <vector>

#include "services/common/port_keeper.hpp"
#include "services/common/service.hpp"

namespace airseg {

class PortService : public Service {
  public:
    PortService(std::string name, ServiceContext& ctx, std::vector<PortKeeperConfig> ports);

    bool all_open() const;

  protected:
    void on_start() override;
    void on_stop() override;

  private:
    void update_health();
    std::vector<std::unique_ptr<PortKeeper>> keepers_;
};

}  // namespace airseg
