#include <gpiod.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "hal/gpio_fake.hpp"
#include "hal/gpio_libgpiod.hpp"
#include "hal/gpio_pulse.hpp"
#include "tests/unit/hal/run_until.hpp"

namespace airseg::hal {
namespace {

using test::run_until;

GpioLineRequest output_at(const std::string& chip, unsigned offset, bool initial = false) {
    GpioLineRequest r;
    r.chip = chip;
    r.offset = offset;
    r.initial_value = initial;
    return r;
}

GpioLineRequest by_name(const std::string& name, GpioDirection direction = GpioDirection::Output) {
    GpioLineRequest r;
    r.line_name = name;
    r.direction = direction;
    return r;
}

TEST(HalGpioRequestTest, NeedsExactlyOneWayToAddressALine) {
    EXPECT_EQ(GpioLineRequest::validate(GpioLineRequest{}).size(), 1u);
    auto both = output_at("gpiochip0", 3);
    both.line_name = "LED";
    const auto errors = GpioLineRequest::validate(both);
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_NE(errors[0].find("LED"), std::string::npos);
    EXPECT_TRUE(GpioLineRequest::validate(output_at("gpiochip0", 3)).empty());
    EXPECT_EQ(output_at("gpiochip1", 7).describe(), "gpiochip1:7");
}

class HalFakeGpioTest : public ::testing::Test {
  protected:
    void SetUp() override {
        gpio_.add_line("gpiochip0", 17, "STATUS_LED");
        gpio_.add_line("gpiochip0", 18, "APM_RESET");
        gpio_.add_line("gpiochip1", 2, "ARM_SWITCH");
    }
    ManualClock clock_;
    FakeGpio gpio_{clock_};
};

TEST_F(HalFakeGpioTest, RecordsEveryLevelWithItsTime) {
    const auto r = gpio_.request(output_at("gpiochip0", 17, true));
    ASSERT_TRUE(r.ok()) << r.message;
    const TimePoint t0 = clock_.now();
    clock_.advance(milliseconds(10));
    EXPECT_FALSE(r.line->set(false));
    clock_.advance(milliseconds(5));
    EXPECT_FALSE(r.line->set(true));
    EXPECT_TRUE(r.line->get());
    EXPECT_EQ(r.line->name(), "gpiochip0:17");

    const auto h = gpio_.history("STATUS_LED");
    ASSERT_EQ(h.size(), 3u);
    EXPECT_EQ(h[0].at, t0);
    EXPECT_TRUE(h[0].value);
    EXPECT_EQ(h[1].at, t0 + milliseconds(10));
    EXPECT_FALSE(h[1].value);
    EXPECT_EQ(h[2].at, t0 + milliseconds(15));
    EXPECT_EQ(gpio_.history("gpiochip0:17").size(), 3u) << "chip:offset and name address the same line";
}

TEST_F(HalFakeGpioTest, FindsLinesByNameAcrossChips) {
    const auto r = gpio_.request(by_name("ARM_SWITCH", GpioDirection::Input));
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_EQ(r.line->name(), "gpiochip1:2");
    EXPECT_FALSE(r.line->get());
    gpio_.drive_input("ARM_SWITCH", true);
    EXPECT_TRUE(r.line->get());
    EXPECT_TRUE(r.line->set(true)) << "an input cannot be driven";
}

TEST_F(HalFakeGpioTest, UnknownLinesAndDoubleRequestsFailWithTheLineNamed) {
    const auto missing = gpio_.request(by_name("NO_SUCH_LINE"));
    EXPECT_FALSE(missing.ok());
    EXPECT_EQ(missing.error, std::errc::no_such_file_or_directory);
    EXPECT_NE(missing.message.find("NO_SUCH_LINE"), std::string::npos) << missing.message;
    EXPECT_FALSE(gpio_.request(output_at("gpiochip0", 99)).ok());

    auto held = gpio_.request(output_at("gpiochip0", 18));
    ASSERT_TRUE(held.ok());
    const auto again = gpio_.request(by_name("APM_RESET"));
    EXPECT_EQ(again.error, std::errc::device_or_resource_busy);
    held.line.reset();
    EXPECT_FALSE(gpio_.is_requested("APM_RESET"));
    EXPECT_TRUE(gpio_.request(by_name("APM_RESET")).ok()) << "a released line can be requested again";
}

TEST(HalGpioPulseTest, HoldsTheLineActiveForTheWidthThenReleasesIt) {
    boost::asio::io_context io;
    SteadyClock clock;
    FakeGpio gpio(clock);
    gpio.add_line("gpiochip0", 18, "APM_RESET");
    auto r = gpio.request(by_name("APM_RESET"));
    ASSERT_TRUE(r.ok());
    bool done = false;
    std::error_code result = std::make_error_code(std::errc::io_error);
    pulse(io.get_executor(), r.line, milliseconds(20), [&](std::error_code ec) {
        done = true;
        result = ec;
    });
    EXPECT_TRUE(gpio.value("APM_RESET")) << "active as soon as pulse() returns";
    ASSERT_TRUE(run_until(io, [&] { return done; }));
    EXPECT_FALSE(result);
    const auto h = gpio.history("APM_RESET");
    ASSERT_EQ(h.size(), 3u);  // initial inactive, active, inactive
    EXPECT_FALSE(h[0].value);
    EXPECT_TRUE(h[1].value);
    EXPECT_FALSE(h[2].value);
    EXPECT_GE(h[2].at - h[1].at, milliseconds(20));
}

// ---- libgpiod backend: error paths run everywhere; line I/O needs a chip -------------------------------

bool have_gpiochip() {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
        if (entry.path().filename().string().rfind("gpiochip", 0) == 0) {
            return true;
        }
    }
    return false;
}

// A chip made by the kernel's gpio-sim or gpio-mockup drivers (if an administrator loaded one) can be toggled
// freely; a real board's chips are never driven by this test.
std::string find_simulated_chip() {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("gpiochip", 0) != 0) {
            continue;
        }
        gpiod_chip* chip = gpiod_chip_open(entry.path().c_str());
        if (chip == nullptr) {
            continue;
        }
        const std::string label = gpiod_chip_label(chip);
        gpiod_chip_close(chip);
        if (label.rfind("gpio-mockup", 0) == 0 || label.rfind("gpio-sim", 0) == 0) {
            return entry.path().string();
        }
    }
    return {};
}

TEST(HalLibgpiodTest, MissingChipIsReportedByName) {
    LibgpiodFactory gpio;
    const auto r = gpio.request(output_at("gpiochip-airseg-missing", 0));
    EXPECT_FALSE(r.ok());
    EXPECT_TRUE(r.error);
    EXPECT_NE(r.message.find("gpiochip-airseg-missing"), std::string::npos) << r.message;
}

TEST(HalLibgpiodTest, MissingLineNameIsReportedByName) {
    LibgpiodFactory gpio;
    const auto r = gpio.request(by_name("AIRSEG_NO_SUCH_LINE"));
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.message.find("AIRSEG_NO_SUCH_LINE"), std::string::npos) << r.message;
}

TEST(HalLibgpiodTest, InvalidRequestIsRejectedBeforeTouchingTheKernel) {
    LibgpiodFactory gpio;
    const auto r = gpio.request(GpioLineRequest{});
    EXPECT_EQ(r.error, std::errc::invalid_argument);
}

TEST(HalLibgpiodTest, OffsetBeyondTheChipIsRejected) {
    if (!have_gpiochip()) {
        GTEST_SKIP() << "no /dev/gpiochip* on this machine";
    }
    LibgpiodFactory gpio;
    const auto r = gpio.request(output_at("gpiochip0", 100000));
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.message.find("out of range"), std::string::npos) << r.message;
}

TEST(HalLibgpiodTest, DrivesALineOnASimulatedChip) {
    if (!have_gpiochip()) {
        GTEST_SKIP() << "no /dev/gpiochip* on this machine";
    }
    const std::string chip = find_simulated_chip();
    if (chip.empty()) {
        GTEST_SKIP() << "no gpio-sim or gpio-mockup chip loaded; real chips are not driven by tests";
    }
    LibgpiodFactory gpio;
    auto r = gpio.request(output_at(chip, 0));
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_FALSE(r.line->set(true));
    EXPECT_TRUE(r.line->get());
    EXPECT_FALSE(r.line->set(false));
    EXPECT_FALSE(r.line->get());
    const auto busy = gpio.request(output_at(chip, 0));
    EXPECT_FALSE(busy.ok()) << "a held line must not be handed out twice";
}

}  // namespace
}  // namespace airseg::hal
