#pragma once
// Wires airsegd together: one io_context run by a thread pool, the bus, the services, signals, and systemd.
#include <memory>

#include "daemon/cli.hpp"
#include "daemon/config.hpp"

namespace airseg::daemon {

class App {
  public:
    App(CliOptions options, Config config);
    ~App();

    /// Runs until SIGTERM/SIGINT; returns the process exit code.
    int run();

  private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace airseg::daemon
