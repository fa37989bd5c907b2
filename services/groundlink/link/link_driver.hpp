#pragma once
// Runs a ground-link Transport core on an asio strand: bytes read from the paths go in, frames the core
// releases (already paced to the link rate) go out at once, and one timer follows the core's earliest
// deadline. Used by airsegd's ground-link service and by airsegctl, over serial ports or UDP.
#include <array>
#include <functional>
#include <span>
#include <vector>

#include "services/common/asio.hpp"
#include "services/common/deadline_timer.hpp"
#include "services/groundlink/transport/transport.hpp"

namespace airseg::groundlink {

class LinkDriver {
  public:
    /// Writes one frame to a path now; returns false when the path cannot take it (port closed, queue full).
    using Writer = std::function<bool(std::vector<std::uint8_t> frame)>;
    struct Handlers {
        std::function<void(Delivered)> on_message;
        std::function<void(const TransportEvent&)> on_event;
    };

    /// `wakes`: where the daemon's periodic work waits to share a wake-up (may be null).
    LinkDriver(Strand strand, TransportConfig config, Handlers handlers,
               WakeSharing* wakes = nullptr);
    LinkDriver(const LinkDriver&) = delete;
    LinkDriver& operator=(const LinkDriver&) = delete;

    /// Attaches (or, with an empty writer, detaches) the port of `path`. A detached path is not polled.
    void set_writer(std::size_t path, Writer writer);

    // Everything below runs on the strand.
    void handle_bytes(std::size_t path, std::span<const std::uint8_t> bytes);
    SendResult send_safe(std::uint8_t priority, std::span<const std::uint8_t> msg);
    SendResult send_fast(std::uint8_t priority, std::uint16_t topic, std::span<const std::uint8_t> msg);
    void stop();

    /// Runs `sends` (calls of send_safe/send_fast) and hands the core's frames to the paths once, after all
    /// of them: messages queued at one instant share a frame instead of the second waiting a frame time
    /// behind the first (a wake-up of its own on an idle link).
    template <typename Sends>
    void batch(Sends&& sends) {
        if (pumping_) {
            sends();  // already inside a pump (a handler sending): that pump goes round again
            return;
        }
        pumping_ = true;
        struct Release {
            LinkDriver& driver;
            ~Release() {
                driver.pumping_ = false;
                driver.pump();
            }
        } release{*this};
        sends();
    }

    const Transport& core() const { return core_; }
    const LinkStats& stats() const { return core_.stats(); }
    bool link_up() const { return core_.link_up(); }
    /// Frames the core released that a path refused to take.
    std::uint64_t write_refusals() const { return write_refusals_; }

  private:
    void pump();
    void arm_timer();

    Transport core_;
    Handlers handlers_;
    DeadlineTimer timer_;
    std::array<Writer, kMaxPaths> writers_;
    bool pumping_ = false;
    bool pump_again_ = false;
    bool stopped_ = false;
    std::uint64_t write_refusals_ = 0;
};

}  // namespace airseg::groundlink
