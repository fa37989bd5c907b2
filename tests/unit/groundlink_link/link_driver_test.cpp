// The transport driver on a real io_context.
#include "services/groundlink/link/link_driver.hpp"

#include <gtest/gtest.h>

namespace airseg::groundlink {
namespace {

using namespace std::chrono_literals;

// A path without a port (missing device, or between reopen attempts) must leave the event loop idle between
// the transport's own deadlines (a hello every 500 ms): its frames are dropped, so the send deadline moves
// on.
TEST(LinkDriver, APathWithoutAPortDoesNotSpinTheEventLoop) {
    asio::io_context io;
    TransportConfig config;
    config.boot_nonce = 42;
    LinkDriver driver(asio::make_strand(io), config, LinkDriver::Handlers{});
    const std::uint8_t hello[] = {1, 2, 3};
    driver.send_safe(0, hello);
    const std::size_t handlers_run = io.run_for(600ms);
    // A hello or two and a Safe retransmission or two; a spinning timer runs hundreds of thousands.
    EXPECT_LT(handlers_run, 50U);
    EXPECT_GT(driver.write_refusals(), 0U) << "the frames of the portless path were taken and dropped";
    driver.stop();
}

}  // namespace
}  // namespace airseg::groundlink
