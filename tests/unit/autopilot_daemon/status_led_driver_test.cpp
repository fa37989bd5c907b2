// The status LED adapter on a fake GPIO chip with a real bus and io_context: it follows the autopilot status
// and the ground link's status section, and leaves the LED off when destroyed. Timing itself is checked in
// simulated time (tests/unit/autopilot/status_led_test.cpp); here only the order of the levels counts.
#include "daemon/autopilot_status_led.hpp"

#include <gtest/gtest.h>

#include "hal/gpio_fake.hpp"
#include "services/groundlink/link_state.hpp"
#include "tests/unit/hal/run_until.hpp"

namespace airseg::daemon {
namespace {

using hal::test::run_until;

TEST(StatusLedDriver, BlinksWhileBootingAndStaysMostlyOnWhenReadyWithAGroundLink) {
    asio::io_context io;
    hal::SteadyClock clock;
    hal::FakeGpio gpio(clock);
    gpio.add_line("gpiochip0", 18, "STATUS_LED");
    hal::GpioLineRequest req;
    req.line_name = "STATUS_LED";
    auto r = gpio.request(req);
    ASSERT_TRUE(r.ok()) << r.message;
    Bus bus;
    {
        StatusLedDriver led(bus, asio::make_strand(io), r.line);
        // Booting: 100 ms on, 100 ms off.
        ASSERT_TRUE(run_until(io, [&] { return gpio.history("STATUS_LED").size() >= 5; }));

        autopilot::AutopilotStatus ready;
        ready.link_up = true;
        ready.ready = true;
        bus.publish_latest(ready);
        bus.publish_latest(groundlink::LinkState{true});
        // LinkUp starts with 1.9 s on: the line goes on and stays on.
        const auto before = gpio.history("STATUS_LED").size();
        ASSERT_TRUE(run_until(io, [&] {
            const auto h = gpio.history("STATUS_LED");
            return h.size() > before && h.back().value &&
                   std::chrono::steady_clock::now() - h.back().at > std::chrono::milliseconds(400);
        }));
        EXPECT_TRUE(gpio.value("STATUS_LED"));
    }
    EXPECT_FALSE(gpio.value("STATUS_LED"));
    hal::test::run_until_idle(io);
    EXPECT_FALSE(gpio.value("STATUS_LED")) << "no timer may fire after destruction";
}

}  // namespace
}  // namespace airseg::daemon
