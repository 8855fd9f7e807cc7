// The JSON writer (study/json.hpp) and the reader the shard merge uses (src/study/json_read.hpp).
#include "../src/study/json_read.hpp"

#include "tethash/error.hpp"
#include "tethash/study/json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tethash {
namespace {

using study::JsonWriter;

TEST(StudyJson, QuotesEscapeQuotesBackslashesAndControlCharacters)
{
    EXPECT_EQ(study::json_quote("plain"), "\"plain\"");
    EXPECT_EQ(study::json_quote("say \"hi\"\\"), R"("say \"hi\"\\")");
    EXPECT_EQ(study::json_quote("a\nb\tc\rd\be\ff"), R"("a\nb\tc\rd\be\ff")");
    EXPECT_EQ(study::json_quote(std::string("\x01\x1f\x7f", 3)), R"("\u0001\u001f\u007f")");
    EXPECT_EQ(study::json_quote(std::string("nul\0end", 7)), R"("nul\u0000end")");
    EXPECT_EQ(study::json_quote("héllo ✓"), "\"héllo ✓\""); // UTF-8 passes unchanged
}

TEST(StudyJson, NumbersRoundTripAndNonFiniteIsNull)
{
    for (const double v :
         {0.0, -0.0, 0.1, 1.0 / 3.0, 1e-300, 6.02214076e23, -2.5, 4096.0, 5e-324, std::numeric_limits<double>::max()}) {
        const std::string text = study::json_number(v);
        EXPECT_TRUE(study::is_json_number(text)) << text;
        EXPECT_EQ(std::strtod(text.c_str(), nullptr), v) << text;
    }
    EXPECT_EQ(study::json_number(0.1), "0.1");
    EXPECT_EQ(study::json_number(17), "17");
    EXPECT_EQ(study::json_number(std::nan("")), "null");
    EXPECT_EQ(study::json_number(std::numeric_limits<double>::infinity()), "null");
    EXPECT_EQ(study::json_number(-std::numeric_limits<double>::infinity()), "null");
}

TEST(StudyJson, NumberTextIsCheckedAgainstTheGrammar)
{
    for (const char* yes : {"0", "-1", "1.5", "1e5", "1E-5", "-0.25e+3", "1009"})
        EXPECT_TRUE(study::is_json_number(yes)) << yes;
    for (const char* no : {"", "-", "+1", ".5", "1.", "01", "1e", "nan", "inf", "0x10", "x1", "1,2", " 1"})
        EXPECT_FALSE(study::is_json_number(no)) << no;
    JsonWriter j;
    j.begin_array().number_text("1.5").number_text("x2").number_text("").number_text("nan").end_array();
    EXPECT_EQ(j.str(), R"([1.5, "x2", null, "nan"])");
}

TEST(StudyJson, NestingAndLayout)
{
    JsonWriter j;
    j.begin_object()
        .member("name", "a \"b\"")
        .member("count", 3)
        .member("ok", true)
        .member("x", std::nan(""))
        .key("shard")
        .begin_object(JsonWriter::inline_layout)
        .member("index", 0)
        .key("list")
        .begin_array(JsonWriter::block_layout) // inside an inline container: inline
        .value(1)
        .value(2.5)
        .end_array()
        .end_object()
        .key("rows")
        .begin_array(JsonWriter::block_layout)
        .begin_object(JsonWriter::inline_layout)
        .member("p", 1)
        .end_object()
        .begin_array()
        .end_array()
        .end_array()
        .key("empty")
        .begin_object()
        .end_object()
        .end_object();
    EXPECT_EQ(j.str(), "{\n"
                       "  \"name\": \"a \\\"b\\\"\",\n"
                       "  \"count\": 3,\n"
                       "  \"ok\": true,\n"
                       "  \"x\": null,\n"
                       "  \"shard\": {\"index\": 0, \"list\": [1, 2.5]},\n"
                       "  \"rows\": [\n"
                       "    {\"p\": 1},\n"
                       "    []\n"
                       "  ],\n"
                       "  \"empty\": {}\n"
                       "}");
}

TEST(StudyJson, MisuseIsALogicError)
{
    EXPECT_THROW(JsonWriter().begin_object().value(1), std::logic_error);    // no key
    EXPECT_THROW(JsonWriter().begin_array().key("k"), std::logic_error);     // key in an array
    EXPECT_THROW(JsonWriter().begin_array().end_object(), std::logic_error); // wrong closing
    EXPECT_THROW(JsonWriter().begin_object().key("k").end_object(), std::logic_error);
    EXPECT_THROW((void)JsonWriter().begin_object().str(), std::logic_error); // still open
    EXPECT_THROW(JsonWriter().value(1).value(2), std::logic_error);          // two documents
}

TEST(StudyJson, TheReaderReadsWhatTheWriterWrites)
{
    JsonWriter j;
    j.begin_object()
        .member("sweep", "cell-size")
        .member("points_total", 24)
        .member("note", std::string("tab\there \"q\" \x01 ✓"))
        .key("shard")
        .begin_object(JsonWriter::inline_layout)
        .member("index", 1)
        .member("count", 3)
        .end_object()
        .key("values")
        .begin_array()
        .value(0.1)
        .value(-1e-300)
        .value(false)
        .null()
        .end_array()
        .end_object();
    const study::JsonValue v = study::parse_json(j.str(), "test");
    ASSERT_EQ(v.kind, study::JsonValue::object);
    ASSERT_NE(v.find("sweep"), nullptr);
    EXPECT_EQ(v.find("sweep")->text, "cell-size");
    EXPECT_EQ(v.find("points_total")->num, 24);
    EXPECT_EQ(v.find("note")->text, std::string("tab\there \"q\" \x01 ✓"));
    EXPECT_EQ(v.find("shard")->find("count")->num, 3);
    const auto& values = v.find("values")->items;
    ASSERT_EQ(values.size(), 4u);
    EXPECT_EQ(values[0].num, 0.1);
    EXPECT_EQ(values[1].num, -1e-300);
    EXPECT_EQ(values[2].kind, study::JsonValue::boolean);
    EXPECT_EQ(values[3].kind, study::JsonValue::null);
    EXPECT_EQ(v.find("missing"), nullptr);
    EXPECT_EQ(study::parse_json(R"("\u00e9\ud83d\ude00\/")", "test").text, "é😀/");
}

TEST(StudyJson, TheReaderRejectsWhatIsNotJson)
{
    for (const char* bad : {"", "{", "{\"a\" 1}", "{\"a\": 1,}", "[1 2]", "\"open", "tru", "01", "{\"a\": 1} x",
                            "'single'", "[NaN]", "\"a\nb\""}) {
        try {
            study::parse_json(bad, "shard/study.json");
            ADD_FAILURE() << "accepted: " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("shard/study.json: invalid JSON at line"), std::string::npos)
                << e.what();
        }
    }
}

} // namespace
} // namespace tethash
