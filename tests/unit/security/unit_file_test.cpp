// The shipped systemd unit never runs airsegd, or any command of its own, with root's privileges.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

/// Key → every value it is given in the [Service] section, in order.
std::multimap<std::string, std::string> service_section(const std::string& text) {
    std::multimap<std::string, std::string> out;
    std::istringstream in(text);
    bool in_service = false;
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') {
            continue;
        }
        if (line[0] == '[') {
            in_service = line == "[Service]";
            continue;
        }
        const auto eq = line.find('=');
        if (in_service && eq != std::string::npos) {
            out.emplace(line.substr(0, eq), line.substr(eq + 1));
        }
    }
    return out;
}

std::string only(const std::multimap<std::string, std::string>& s, const std::string& key) {
    EXPECT_EQ(s.count(key), 1u) << key;
    const auto it = s.find(key);
    return it == s.end() ? std::string("<missing>") : it->second;
}

TEST(SystemdUnit, RunsTheDaemonAsTheAirsegUserWithoutAnyPrivilege) {
    const auto s = service_section(read_file(source_path("systemd/airsegd.service")));
    ASSERT_FALSE(s.empty());
    EXPECT_EQ(only(s, "User"), "airseg");
    EXPECT_EQ(only(s, "Group"), "airseg");
    EXPECT_EQ(s.count("DynamicUser"), 0u);
    EXPECT_EQ(only(s, "CapabilityBoundingSet"), "");
    EXPECT_EQ(only(s, "AmbientCapabilities"), "");
    EXPECT_EQ(only(s, "NoNewPrivileges"), "yes");
    // No command runs with full privileges: '+' and '!' prefixes, and the retired PermissionsStartOnly.
    EXPECT_EQ(s.count("PermissionsStartOnly"), 0u);
    for (const auto& [key, value] : s) {
        if (key.rfind("Exec", 0) == 0) {
            const auto flags = value.substr(0, value.find_first_not_of("@-:+!"));
            EXPECT_EQ(flags.find_first_of("+!"), std::string::npos) << key << "=" << value;
        }
    }
    EXPECT_NE(only(s, "ExecStart").find("/usr/sbin/airsegd"), std::string::npos);
}

}  // namespace
}  // namespace airseg::test
