// The map server's request reading (Beast's parser under the map's limits) and its replies.
#include <gtest/gtest.h>

#include "ground/map/http.hpp"
#include "ground/map/request_reader.hpp"

namespace airseg::ground::http {
namespace {

using State = RequestReader::State;

TEST(MapHttp, ARequestArrivingByteByByteIsReadOnce) {
    const std::string text =
        "POST /api/command?x=1 HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
        "Content-Length: 20\r\n\r\n{\"cmd\":\"plan.pause\"}";
    RequestReader r;
    for (std::size_t i = 0; i + 1 < text.size(); ++i) {
        ASSERT_EQ(r.feed(text.substr(i, 1)), State::Incomplete) << i;
    }
    ASSERT_EQ(r.feed(text.substr(text.size() - 1)), State::Done);
    const auto req = r.take();
    EXPECT_EQ(req.method, "POST");
    EXPECT_EQ(req.path, "/api/command");
    EXPECT_EQ(req.query, "x=1");
    EXPECT_EQ(req.header("content-type"), "application/json");
    EXPECT_EQ(req.body, "{\"cmd\":\"plan.pause\"}");
    EXPECT_TRUE(req.keep_alive);
    EXPECT_EQ(r.state(), State::Incomplete);
    EXPECT_FALSE(r.started());
}

TEST(MapHttp, PipelinedRequestsAreReadOneAfterAnother) {
    RequestReader r;
    ASSERT_EQ(r.feed("GET /a HTTP/1.1\r\nHost: x\r\n\r\nGET /b HTTP/1.1\r\nHost: x\r\nConnection: "
                     "close\r\n\r\nGET /c"),
              State::Done);
    EXPECT_EQ(r.take().path, "/a");
    ASSERT_EQ(r.feed({}), State::Done) << "the second was already buffered";
    const auto b = r.take();
    EXPECT_EQ(b.path, "/b");
    EXPECT_FALSE(b.keep_alive);
    EXPECT_EQ(r.feed({}), State::Incomplete);
    EXPECT_TRUE(r.started()) << "the third has begun";
    ASSERT_EQ(r.feed(" HTTP/1.0\r\n\r\n"), State::Done);
    const auto c = r.take();
    EXPECT_EQ(c.version, 10u);
    EXPECT_FALSE(c.keep_alive) << "HTTP/1.0 closes unless it asks otherwise";
}

TEST(MapHttp, PathsArePercentDecoded) {
    RequestReader r;
    ASSERT_EQ(r.feed("GET /static/a%20b.js HTTP/1.1\r\nHost: x\r\n\r\n"), State::Done);
    EXPECT_EQ(r.take().path, "/static/a b.js");
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
        {"GET /x HTTP/1.2\r\nHost: a\r\n\r\n", 505, "HTTP/1.1"},
        {"GET /x HTTP/1.1\r\nHost: a\r\nbad header\r\n\r\n", 400, "malformed header"},
        {"GET /x HTTP/1.1\r\nHost: a\nX: y\r\n\r\n", 400, "bare LF"},
        {"GET /x HTTP/1.1\r\nHost: a\rX: y\r\n\r\n", 400, "CRLF"},
        {"GET / HTTP/1.1\nHost: a\n\n", 400, "bare LF"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\nx", 400,
         "Content-Length"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: -1\r\n\r\n", 400, "not a number"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nTransfer-Encoding: chunked\r\n\r\n", 501, "Content-Length"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 99999999999\r\n\r\n", 413, "larger than"},
        {"POST /x HTTP/1.1\r\nHost: a\r\nContent-Length: 12x\r\n\r\n", 400, "not a number"},
        {"GET /%zz HTTP/1.1\r\nHost: a\r\n\r\n", 400, "percent"},
        {"GET /\x80 HTTP/1.1\r\nHost: a\r\n\r\n", 400, "non-ASCII"},
        {"GET /" + std::string(3000, 'a') + " HTTP/1.1\r\nHost: a\r\n\r\n", 414, "longer than"},
    };
    for (const auto& c : cases) {
        RequestReader r;
        EXPECT_EQ(r.feed(c.text), State::Failed) << c.text;
        EXPECT_EQ(r.error_status(), c.status) << c.text;
        EXPECT_NE(r.error().find(c.why), std::string::npos) << c.text << " -> " << r.error();
    }
}

TEST(MapHttp, HeadsAndHeaderCountsAreBounded) {
    RequestReader r(Limits{1024, 64, 2048, 1024});
    EXPECT_EQ(r.feed("GET / HTTP/1.1\r\nHost: a\r\n"), State::Incomplete);
    EXPECT_EQ(r.feed("X-Long: " + std::string(2000, 'a')), State::Failed);
    EXPECT_EQ(r.error_status(), 431);

    std::string many = "GET / HTTP/1.1\r\nHost: a\r\n";
    for (int i = 0; i < 64; ++i) {
        many += "X-" + std::to_string(i) + ": y\r\n";
    }
    RequestReader counted;
    EXPECT_EQ(counted.feed(many + "\r\n"), State::Failed);
    EXPECT_EQ(counted.error_status(), 431);
    EXPECT_NE(counted.error().find("more than 64 headers"), std::string::npos);

    RequestReader ahead;
    ASSERT_EQ(ahead.feed("GET / HTTP/1.1\r\nHost: a\r\n\r\n"), State::Done);
    // Sent ahead of the answers without end: bounded, not buffered for ever.
    State last = State::Done;
    for (int i = 0; i < 1000 && last != State::Failed; ++i) {
        last = ahead.feed(std::string(8192, 'G'));
    }
    EXPECT_EQ(last, State::Failed);
    EXPECT_EQ(ahead.error_status(), 431);
}

TEST(MapHttp, RepliesCarryTheirLengthTypeAndFraming) {
    const auto r = render(error_reply(404, "nope", {{"Allow", "GET"}}), {11, false, false});
    EXPECT_TRUE(r.starts_with("HTTP/1.1 404 Not Found\r\n")) << r;
    EXPECT_NE(r.find("Content-Length: 20\r\n"), std::string::npos) << r;
    EXPECT_NE(r.find("Allow: GET\r\n"), std::string::npos);
    EXPECT_NE(r.find("Connection: close\r\n"), std::string::npos);
    EXPECT_NE(r.find("X-Content-Type-Options: nosniff\r\n"), std::string::npos);
    EXPECT_TRUE(r.ends_with("\r\n\r\n404 Not Found: nope\n")) << r;

    const Reply ok{200, "text/plain", "body", {}};
    const auto kept = render(ok, {11, false, true});
    EXPECT_EQ(kept.find("Connection:"), std::string::npos) << "HTTP/1.1 stays open by default";
    const auto head = render(ok, {11, true, true});
    EXPECT_TRUE(head.ends_with("\r\n\r\n")) << "HEAD: no body";
    EXPECT_NE(head.find("Content-Length: 4\r\n"), std::string::npos) << "but the length of the GET's";
    const auto old = render(ok, {10, false, true});
    EXPECT_TRUE(old.starts_with("HTTP/1.0 200 OK\r\n"));
    EXPECT_NE(old.find("Connection: keep-alive\r\n"), std::string::npos) << old;
    EXPECT_TRUE(render(error_reply(413, "x"), {}).starts_with("HTTP/1.1 413 Content Too Large\r\n"));

    const auto stream = render_stream_head({11, false, true});
    EXPECT_NE(stream.find("Content-Type: text/event-stream\r\n"), std::string::npos);
    EXPECT_NE(stream.find("Connection: close\r\n"), std::string::npos);
    EXPECT_EQ(stream.find("Content-Length"), std::string::npos);

    EXPECT_EQ(content_type_for("leaflet.js"), "text/javascript; charset=utf-8");
    EXPECT_EQ(content_type_for("marker-icon.png"), "image/png");
    EXPECT_EQ(content_type_for("x.bin"), "application/octet-stream");
}

}  // namespace
}  // namespace airseg::ground::http
