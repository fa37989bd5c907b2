// A fleet command's MQTT id carried to the vehicle as its request id, in a form the vehicle's record takes.
#include <gtest/gtest.h>

#include <string>

#include "ground/fleet_command.hpp"
#include "services/common/command_record.hpp"

namespace airseg::ground {
namespace {

using Json = nlohmann::json;

std::string id_on_board(const Json& request) {
    const auto id = CommandRecord::id_of(request);
    EXPECT_TRUE(id.error.empty()) << id.error;
    return id.id.value_or("(none)");
}

TEST(FleetCommand, TheMqttIdBecomesTheVehiclesRequestId) {
    const Json append = {{"cmd", "plan_append"}, {"plan", "x"}};
    EXPECT_EQ(id_on_board(with_request_id(append, "op-7")), "mqtt:op-7");
    EXPECT_EQ(id_on_board(with_request_id(append, 42)), "mqtt:42");
    EXPECT_EQ(with_request_id(append, "op-7")["plan"], "x") << "the request itself is unchanged";
    EXPECT_EQ(with_request_id(append, "op-7"), with_request_id(append, "op-7"))
        << "the same command delivered again names the same record entry";
    EXPECT_NE(with_request_id(append, "op-7"), with_request_id(append, "op-8"));
}

TEST(FleetCommand, AnIdTheVehicleWouldRefuseIsFingerprinted) {
    const Json stop = {{"cmd", "stop"}};
    const std::string long_id(200, 'a');
    const auto long_one = id_on_board(with_request_id(stop, long_id));
    EXPECT_EQ(long_one.rfind("mqtt:#", 0), 0u) << long_one;
    EXPECT_LE(long_one.size(), CommandRecord::kMaxIdLength);
    EXPECT_NE(long_one, id_on_board(with_request_id(stop, long_id + "b")));
    const auto spaced = id_on_board(with_request_id(stop, "run 12"));
    EXPECT_EQ(spaced.rfind("mqtt:#", 0), 0u) << spaced;
    EXPECT_EQ(id_on_board(with_request_id(stop, "")).rfind("mqtt:#", 0), 0u);
}

TEST(FleetCommand, ARequestThatNamesItsOwnIdKeepsIt) {
    const Json request = {{"cmd", "stop"}, {"request_id", "operator-1"}};
    EXPECT_EQ(with_request_id(request, "op-7")["request_id"], "operator-1");
}

}  // namespace
}  // namespace airseg::ground
