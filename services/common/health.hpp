#pragma once
// Health of every service, shared by the status service (what it reports) and the watchdog (whether the
// process as a whole is alive). Services call it from their own strands, so it is the one locked table.
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "base/time.hpp"

namespace airseg {

enum class Health { Up, Degraded, Down };

const char* to_string(Health h);

struct ServiceHealth {
    std::string name;
    Health health = Health::Down;
    std::chrono::system_clock::time_point since;  // wall time of the last health change, for people
    std::string error;                            // why it is not up; empty when up
    TimePoint last_progress;                      // steady time the service last showed it runs
};

class HealthRegistry {
  public:
    /// Registers a service; it starts DOWN with the given reason until it says otherwise.
    void add(const std::string& name, TimePoint now, std::string reason = "starting");

    /// Records a health change. Returns true when health or error actually changed.
    bool set(const std::string& name, Health health, std::string error = {});

    /// The service's strand ran: it is not stuck.
    void progress(const std::string& name, TimePoint now);

    std::vector<ServiceHealth> snapshot() const;

    /// Names of services that have not shown progress within `period` before `now` (empty = all alive).
    std::vector<std::string> stalled(TimePoint now, Duration period) const;

  private:
    mutable std::mutex mutex_;
    std::map<std::string, ServiceHealth> services_;
};

}  // namespace airseg
