// Text from outside: UTF-8 checked where it enters, made printable where it is only shown.
#include "base/utf8.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace airseg {
namespace {

TEST(Utf8, WellFormedTextPassesAndEachKindOfMalformedByteIsFound) {
    EXPECT_TRUE(valid_utf8(""));
    EXPECT_TRUE(valid_utf8("plain ASCII"));
    EXPECT_TRUE(valid_utf8("Castelldefels \xc3\xa0 \xe2\x82\xac \xf0\x9f\x9a\x80"));  // à € 🚀
    EXPECT_EQ(first_invalid_utf8("ab\xff"), 2u);                                      // never a UTF-8 byte
    EXPECT_EQ(first_invalid_utf8("a\x80"), 1u);             // a stray continuation byte
    EXPECT_EQ(first_invalid_utf8("a\xc3"), 1u);             // truncated
    EXPECT_EQ(first_invalid_utf8("\xc0\xaf"), 0u);          // overlong '/'
    EXPECT_EQ(first_invalid_utf8("\xe0\x80\xaf"), 0u);      // overlong, three bytes
    EXPECT_EQ(first_invalid_utf8("\xed\xa0\x80"), 0u);      // a surrogate (U+D800)
    EXPECT_EQ(first_invalid_utf8("\xf4\x90\x80\x80"), 0u);  // above U+10FFFF
    EXPECT_EQ(first_invalid_utf8("\xc3\x28"), 0u);          // a lead byte without its continuation
}

// The property the daemon relies on: a text valid_utf8 accepts never makes nlohmann's dump throw, and one it
// refuses always would.
TEST(Utf8, ValidUtf8AgreesWithWhatJsonDumpAccepts) {
    std::uint32_t state = 12345;
    for (int i = 0; i < 20000; ++i) {
        std::string text;
        const int length = 1 + i % 6;
        for (int k = 0; k < length; ++k) {
            state = state * 1103515245u + 12345u;
            const auto byte = static_cast<char>((state >> 16) & 0xff);
            text += (state >> 8) % 3 == 0 ? 'a' : byte;
        }
        bool dumped = true;
        try {
            (void)nlohmann::json(text).dump();
        } catch (const nlohmann::json::type_error&) {
            dumped = false;
        }
        ASSERT_EQ(valid_utf8(text), dumped)
            << nlohmann::json(text).dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
    }
}

TEST(Utf8, TextFaultsNameTheByteAndAllowTabsAndLineEnds) {
    EXPECT_FALSE(first_text_fault("a:\tb\r\n  c: d\n"));
    const auto nul = first_text_fault(std::string("name: a\0b\n", 10));
    ASSERT_TRUE(nul);
    EXPECT_EQ(nul->offset, 7u);
    EXPECT_EQ(nul->what(), "a control character (0x00)");
    const auto bad = first_text_fault("name: \"\xff\"\n");
    ASSERT_TRUE(bad);
    EXPECT_EQ(bad->what(), "not valid UTF-8 (byte 0xff)");
    const auto at = position_of("a\nbc\xff", 4);
    EXPECT_EQ(at.line, 2u);
    EXPECT_EQ(at.column, 3u);
}

TEST(Utf8, AnExcerptEscapesAndCutsLongText) {
    EXPECT_EQ(excerpt("ok \xc3\xa0"), "ok \xc3\xa0");
    EXPECT_EQ(excerpt("a\xff\x01"
                      "b"),
              "a\\xff\\x01b");
    const std::string huge(10'000'000, 'v');
    const auto shown = excerpt(huge);
    EXPECT_EQ(shown, std::string(80, 'v') + "… (10000000 bytes)");
    EXPECT_TRUE(valid_utf8(excerpt("\xe2\x82\xac\xe2\x82", 1)));  // never cuts inside a character
}

}  // namespace
}  // namespace airseg
