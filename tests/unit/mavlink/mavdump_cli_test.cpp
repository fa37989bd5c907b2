// airseg-mavdump as a user runs it: files in, files out, exit statuses, messages.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/tree_paths.hpp"
#include "tests/unit/mavlink/golden_frames.hpp"

namespace {

using airseg::mavlink::test::from_hex;

class MavdumpCli : public ::testing::Test {
  protected:
    std::string dir_ = ::testing::TempDir() + "mavdump_cli_" +
                       ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_";

    std::string path(const std::string& name) const { return dir_ + name; }
    static void write(const std::string& file, const std::string& bytes) {
        std::ofstream(file, std::ios::binary) << bytes;
    }
    static std::string read(const std::string& file) {
        std::ifstream in(file, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    }
    // Runs the tool with `args`, stdout and stderr to files; returns the exit status.
    int run(const std::string& args) const {
        const std::string cmd = ::airseg::test::binary_dir() + "/" AIRSEG_MAVDUMP_IN_BUILD " " + args + " >" +
                                path("out") + " 2>" + path("err");
        const int status = std::system(cmd.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    std::string out() const { return read(path("out")); }
    std::string err() const { return read(path("err")); }
};

std::string bytes_of(std::string_view hex) {
    const auto b = from_hex(hex);
    return std::string(b.begin(), b.end());
}

TEST_F(MavdumpCli, HelpDescribesBothDirections) {
    EXPECT_EQ(run("--help"), 0);
    EXPECT_NE(out().find("--encode"), std::string::npos);
    EXPECT_NE(out().find(".tlog"), std::string::npos);
}

TEST_F(MavdumpCli, UnknownOptionIsAUsageError) {
    EXPECT_EQ(run("--bogus"), 2);
    EXPECT_NE(err().find("unrecognised option '--bogus'"), std::string::npos);
}

TEST_F(MavdumpCli, MissingFileIsReportedByName) {
    EXPECT_EQ(run(path("does-not-exist")), 1);
    EXPECT_NE(err().find("does-not-exist"), std::string::npos);
}

TEST_F(MavdumpCli, DecodesAStreamAndSummarisesBadFramesOnStderr) {
    std::string damaged = bytes_of(airseg::mavlink::test::kGpsRawIntV2);
    damaged[20] = static_cast<char>(damaged[20] ^ 0x10);
    write(path("in.bin"), "junk" + bytes_of(airseg::mavlink::test::kHeartbeatV1) + damaged +
                              bytes_of(airseg::mavlink::test::kStatustextV2));
    ASSERT_EQ(run(path("in.bin")), 0);
    std::istringstream lines(out());
    std::vector<std::string> got;
    for (std::string l; std::getline(lines, l);) {
        got.push_back(l);
    }
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[0].rfind(R"({"name":"HEARTBEAT","msgid":0,"sysid":1,"compid":1,"seq":7,"v":1,)", 0), 0u);
    EXPECT_NE(got[1].find(R"("text":"Mission: 1 WP")"), std::string::npos);
    EXPECT_NE(err().find(R"("frames_ok":2)"), std::string::npos) << err();
    EXPECT_NE(err().find(R"("bad_checksum":1)"), std::string::npos) << err();
    EXPECT_NE(err().find(R"("garbage_bytes":4)"), std::string::npos) << err();
}

TEST_F(MavdumpCli, TlogRecordsCarryTheirTimestamps) {
    const std::string ts("\x00\x06\x0A\x24\x18\x1E\x40\x01", 8);  // 1700000000000001 us, big-endian
    write(path("flight.tlog"), ts + bytes_of(airseg::mavlink::test::kHeartbeatV2));
    ASSERT_EQ(run(path("flight.tlog")), 0);
    EXPECT_EQ(out().rfind(R"({"timestamp_us":1700000000000001,"name":"HEARTBEAT")", 0), 0u) << out();
}

TEST_F(MavdumpCli, EncodeThenDecodeGivesTheSameLines) {
    const std::string lines =
        R"({"name":"MISSION_ITEM_INT","msgid":73,"sysid":255,"compid":190,"seq":3,"v":2,"fields":{"target_system":1,)"
        R"("target_component":1,"seq":2,"frame":6,"command":16,"current":0,"autocontinue":1,"param1":0,)"
        R"("param2":2,"param3":0,"param4":"nan","x":-353632621,"y":1491652374,"z":25.5,"mission_type":0}})"
        "\n";
    write(path("in.jsonl"), lines);
    ASSERT_EQ(run("--encode " + path("in.jsonl") + " -o " + path("frames.bin")), 0) << err();
    ASSERT_EQ(run(path("frames.bin")), 0);
    EXPECT_EQ(out(), lines);
}

TEST_F(MavdumpCli, EncodeReportsBadLinesByNumberAndFails) {
    write(path("in.jsonl"),
          "{\"name\":\"HEARTBEAT\"}\n\n{\"name\":\"HEARTBEAT\",\"fields\":{\"nope\":1}}\n{\"name\":}\n");
    EXPECT_EQ(run("--encode " + path("in.jsonl") + " -o " + path("frames.bin")), 1);
    EXPECT_NE(err().find("in.jsonl:3: HEARTBEAT has no field \"nope\""), std::string::npos) << err();
    EXPECT_NE(
        err().find("in.jsonl:4: invalid JSON: syntax error while parsing value - unexpected '}'; expected "
                   "'[', '{', or a literal at byte 8"),
        std::string::npos)
        << err();
    EXPECT_NE(err().find(R"("frames":1,"errors":2)"), std::string::npos) << err();
    EXPECT_EQ(read(path("frames.bin")).size(), 10u + 9u + 2u);
}

}  // namespace
