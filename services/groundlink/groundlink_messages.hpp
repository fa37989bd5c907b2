#pragma once
// Bus messages of the ground-link service.
#include "services/groundlink/telemetry_scheduler.hpp"

namespace airseg::groundlink {

/// A reloaded configuration (SIGHUP) for the telemetry scheduler: its rates replace those set from the
/// ground.
struct TelemetryConfigChanged {
    TelemetrySchedulerConfig config;
};

}  // namespace airseg::groundlink
