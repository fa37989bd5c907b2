#include "services/common/bus.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace airseg {
namespace {

struct Ping {
    int n;
};
struct Position {
    double lat;
};

TEST(Bus, EventsReachEverySubscriberInOrderOnItsStrand) {
    asio::io_context io;
    Bus bus;
    Strand a = asio::make_strand(io), b = asio::make_strand(io);
    std::vector<int> seen_a, seen_b;
    auto sa = bus.subscribe<Ping>(a, [&](const Ping& p) {
        EXPECT_TRUE(a.running_in_this_thread());
        seen_a.push_back(p.n);
    });
    auto sb = bus.subscribe<Ping>(b, [&](const Ping& p) {
        EXPECT_TRUE(b.running_in_this_thread());
        seen_b.push_back(p.n);
    });
    for (int i = 0; i < 100; ++i) {
        bus.publish(Ping{i});
    }
    io.run();
    ASSERT_EQ(seen_a.size(), 100u);
    ASSERT_EQ(seen_b.size(), 100u);
    for (int i = 0; i < 100; ++i) {
        EXPECT_EQ(seen_a[i], i);
        EXPECT_EQ(seen_b[i], i);
    }
}

TEST(Bus, OtherTypesAreNotDelivered) {
    asio::io_context io;
    Bus bus;
    Strand s = asio::make_strand(io);
    int pings = 0;
    auto sub = bus.subscribe<Ping>(s, [&](const Ping&) { ++pings; });
    bus.publish(Position{1.0});
    io.run();
    EXPECT_EQ(pings, 0);
}

TEST(Bus, VariablesCoalesceToTheNewestValue) {
    asio::io_context io;
    Bus bus;
    Strand s = asio::make_strand(io);
    std::vector<double> seen;
    auto sub = bus.subscribe<Position>(s, [&](const Position& p) { seen.push_back(p.lat); });
    for (int i = 1; i <= 50; ++i) {
        bus.publish_latest(Position{double(i)});
    }
    io.run();
    ASSERT_EQ(seen.size(), 1u);  // nothing ran between the publishes: only the newest is delivered
    EXPECT_EQ(seen.back(), 50.0);
    ASSERT_TRUE(bus.latest<Position>().has_value());
    EXPECT_EQ(bus.latest<Position>()->lat, 50.0);
}

struct Mode {
    int number;
    bool operator==(const Mode&) const = default;
};

TEST(Bus, AVariableRepublishedUnchangedWakesNoSubscriber) {
    asio::io_context io;
    Bus bus;
    Strand s = asio::make_strand(io);
    std::vector<int> seen;
    auto sub = bus.subscribe<Mode>(s, [&](const Mode& m) { seen.push_back(m.number); });
    bus.publish_latest(Mode{3});
    io.run();
    io.restart();
    bus.publish_latest(Mode{3});
    EXPECT_EQ(io.poll(), 0u);  // nothing was posted
    io.restart();
    bus.publish_latest(Mode{4});
    bus.publish_latest(Mode{3});  // differs from the retained 4: delivered, coalesced with it
    io.run();
    EXPECT_EQ(seen, (std::vector<int>{3, 3}));
    EXPECT_EQ(bus.latest<Mode>()->number, 3);
}

TEST(Bus, AVariableThatCannotBeComparedIsDeliveredAtEveryPublish) {
    asio::io_context io;
    Bus bus;
    Strand s = asio::make_strand(io);
    int deliveries = 0;
    auto sub = bus.subscribe<Position>(s, [&](const Position&) { ++deliveries; });
    for (int i = 0; i < 3; ++i) {
        bus.publish_latest(Position{1.0});
        io.run();
        io.restart();
    }
    EXPECT_EQ(deliveries, 3);
}

TEST(Bus, LateSubscriberGetsTheCurrentValueOfAVariable) {
    asio::io_context io;
    Bus bus;
    bus.publish_latest(Position{7.5});
    Strand s = asio::make_strand(io);
    std::vector<double> seen;
    auto sub = bus.subscribe<Position>(s, [&](const Position& p) { seen.push_back(p.lat); });
    io.run();
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0], 7.5);
}

TEST(Bus, ResetSubscriptionStopsDeliveriesAlreadyQueued) {
    asio::io_context io;
    Bus bus;
    Strand s = asio::make_strand(io);
    int pings = 0;
    auto sub = bus.subscribe<Ping>(s, [&](const Ping&) { ++pings; });
    bus.publish(Ping{1});
    sub.reset();
    bus.publish(Ping{2});
    io.run();
    EXPECT_EQ(pings, 0);
    EXPECT_FALSE(sub.active());
}

TEST(Bus, ConcurrentPublishersFromManyThreadsLoseNothing) {
    asio::io_context io;
    Bus bus;
    Strand s = asio::make_strand(io);
    int total = 0;  // touched only on the subscriber's strand
    auto sub = bus.subscribe<Ping>(s, [&](const Ping& p) { total += p.n; });
    std::vector<std::thread> publishers;
    for (int t = 0; t < 4; ++t) {
        publishers.emplace_back([&] {
            for (int i = 0; i < 1000; ++i) {
                bus.publish(Ping{1});
            }
        });
    }
    std::vector<std::thread> runners;
    for (int t = 0; t < 2; ++t) {
        runners.emplace_back([&] { io.run(); });
    }
    for (auto& t : publishers) {
        t.join();
    }
    for (auto& t : runners) {
        t.join();
    }
    io.restart();
    io.run();
    EXPECT_EQ(total, 4000);
}

}  // namespace
}  // namespace airseg
