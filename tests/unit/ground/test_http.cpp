// The map server's HTTP parsing: strict, bounded, incremental.
#include <gtest/gtest.h>

#include "ground/map/http.hpp"

namespace airseg::ground::http {
namespace {

using State = RequestParser::State;

TEST(MapHttp, ARequestArrivingByteByByteIsParsedOnce) {
    const std::string text =
        "POST /api/command?x=1 HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
        "Content-Length: 20\r\n\r\n{\"cmd\":\"plan.pause\"}";
    RequestParser p;
    for (std::size_t i = 0; i + 1 < text.size(); ++i) {
        ASSERT_EQ(p.feed(text.substr(i, 1)), State::Incomplete) << i;
    }
    ASSERT_EQ(p.feed(text.substr(text.size() - 1)), State::Done);
    EXPECT_EQ(p.request().method, "POST");
    EXPECT_EQ(p.request().path, "/api/command");
    EXPECT_EQ(p.request().query, "x=1");
    EXPECT_EQ(p.request().header("content-type"), "application/json");
    EXPECT_EQ(p.request().body, "{\"cmd\":\"plan.pause\"}");
}

TEST(MapHttp, PathsArePercentDecoded) {
    RequestParser p;
    ASSERT_EQ(p.feed("GET /static/a%20b.js HTTP/1.1\r\nHost: x\r\n\r\n"), State::Done);
    EXPECT_EQ(p.request().path, "/static/a b.js");
    EXPECT_FALSE(percent_decode("%2"));
    EXPECT_FALSE(percent_decode("%zz"));
    EXPECT_FALSE(percent_decode("a%00b")) << "no NUL in a path";
}

struct Bad {
    std::string text;
    int status;
    std::string why;
};

TEST(MapHttp, MalformedRequestsAreRefusedWithTheirReason) {
    const std::vector<Bad> cases = {
        {"GARBAGE\r\n\r\n", 400, "request line"},
        {"GET /x HTTP/1.1\r\n\r\n", 400, "Host"},
        {"GET x HTTP/1.1\r\nHost: a\r\n\r\n", 400, "starting with /"},
        {"GET /x HTTP/2.0\r\nHost: a\r\n\r\n", 505, "HTTP/1.1"},
        {"GET /x HTTP/1.1\r\nHost: a\r\nbad header\r\n\r\n", 400, "malformed header"},
        {"GET /x HTTP/1.1\r\nHost: a\nX: y\r\n\r\n", 400, "bare CR or LF"},
        {"GET /x HTTP/1.1\r\nHost: a\r\n folded\r\n\r\n", 400, "folded"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 1\r\nContent-Length: 1\r\n\r\nx", 400,
         "more than one"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: -1\r\n\r\n", 400, "not a number"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nTransfer-Encoding: chunked\r\n\r\n", 501, "Content-Length"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 99999999999\r\n\r\n", 413, "larger than"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 999999999999999999999999\r\n\r\n", 413,
         "larger than"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 12x\r\n\r\n", 400, "not a number"},
        {"GET /%zz HTTP/1.1\r\nHost: a\r\n\r\n", 400, "percent"},
    };
    for (const auto& c : cases) {
        RequestParser p;
        EXPECT_EQ(p.feed(c.text), State::Failed) << c.text;
        EXPECT_EQ(p.error_status(), c.status) << c.text;
        EXPECT_NE(p.error().find(c.why), std::string::npos) << c.text << " -> " << p.error();
    }
}

TEST(MapHttp, AnEndlessHeadIsRefusedAtTheLimit) {
    RequestParser p(Limits{1024, 64, 1024});
    EXPECT_EQ(p.feed("GET / HTTP/1.1\r\nHost: a\r\n"), State::Incomplete);
    EXPECT_EQ(p.feed("X-Long: " + std::string(2000, 'a')), State::Failed);
    EXPECT_EQ(p.error_status(), 431);
}

TEST(MapHttp, ResponsesCarryTheirLengthAndType) {
    const auto r = response(404, "text/plain", "nope", {"Allow: GET"});
    EXPECT_TRUE(r.starts_with("HTTP/1.1 404 Not Found\r\n"));
    EXPECT_NE(r.find("Content-Length: 4\r\n"), std::string::npos);
    EXPECT_NE(r.find("Allow: GET\r\n"), std::string::npos);
    EXPECT_TRUE(r.ends_with("\r\n\r\nnope"));
    EXPECT_TRUE(response(200, "text/plain", "body", {}, true).ends_with("\r\n\r\n")) << "HEAD: no body";
    EXPECT_EQ(content_type_for("leaflet.js"), "text/javascript; charset=utf-8");
    EXPECT_EQ(content_type_for("marker-icon.png"), "image/png");
    EXPECT_EQ(content_type_for("x.bin"), "application/octet-stream");
}

}  // namespace
}  // namespace airseg::ground::http
