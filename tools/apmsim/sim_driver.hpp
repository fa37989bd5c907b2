#pragma once
// airseg-apmsim's real-time driver: one RoverSim on a hal::Pty, simulated time = real time × speedup, one
// steady_timer that follows the core's poll_timeout(), the control socket, and the scheduled faults of the
// command line. Everything runs on one strand.
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "hal/asio.hpp"
#include "hal/pty.hpp"
#include "tools/apmsim/options.hpp"
#include "tools/apmsim/rover_sim.hpp"
#include "tools/common/control_socket.hpp"

namespace airseg::apmsim {

class SimDriver {
  public:
    SimDriver(boost::asio::io_context& io, ApmSimOptions options);
    ~SimDriver();
    SimDriver(const SimDriver&) = delete;
    SimDriver& operator=(const SimDriver&) = delete;

    /// Creates the pty and the control socket. Returns an error message naming the path, or empty.
    std::string start();
    /// Cancels timers and closes the control socket and the pty.
    void stop();
    void reboot();

    const RoverSim& sim() const { return *sim_; }
    const hal::Pty& pty() const { return *pty_; }
    TimePoint sim_now() const;

  private:
    TimePoint to_real(TimePoint sim_time) const;
    void pump();
    void arm();
    void schedule_faults();
    void at_sim_time(Duration after_start, std::function<void()> action);
    void on_port_opened();
    std::string unplug();
    std::string replug();
    std::string on_command(const std::string& command);
    void log(const std::string& line) const;
    void log_new_events();
    bool baud_mismatch();
    std::vector<std::uint8_t> noise(std::size_t n);

    ApmSimOptions options_;
    hal::Executor strand_;
    TimePoint real_origin_;
    std::unique_ptr<RoverSim> sim_;
    std::unique_ptr<hal::Pty> pty_;
    std::unique_ptr<toolcommon::ControlSocket> control_;
    boost::asio::steady_timer timer_;
    TimePoint armed_ = kNever;
    std::vector<std::unique_ptr<boost::asio::steady_timer>> fault_timers_;
    std::size_t modes_logged_ = 0;
    std::size_t reached_logged_ = 0;
    bool peer_present_ = false;  // as the board sees it (DTR)
    bool stopped_ = false;
    std::mt19937 noise_rng_;
    unsigned mismatch_logged_ = 0;  // the peer rate last reported as wrong (0: none)
    bool backlog_logged_ = false;   // the peer's unread backlog was reported, and has not cleared since
};

}  // namespace airseg::apmsim
