// Request parsing and line framing of the control protocol (PROTOCOL.md).
#include <gtest/gtest.h>

#include "protocol.hpp"

namespace procam::daemon::proto {
namespace {

using nlohmann::json;

TEST(ParseRequest, AcceptsCommandWithIntegerStringOrNoId) {
  auto r = parseRequest(R"({"cmd":"status","id":7})");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->cmd, "status");
  EXPECT_EQ(r->id, 7);
  r = parseRequest(R"({"id":"a-1","cmd":"pattern","name":"grid"})");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->id, "a-1");
  EXPECT_EQ(r->body["name"], "grid");
  r = parseRequest(R"({"cmd":"version"})");
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->id.is_null());
}

TEST(ParseRequest, RejectsWithTheRightCodeAndKeepsIdWhenReadable) {
  struct Case {
    const char* line;
    const char* code;
    json id;
  } cases[] = {
      {"", code::kParse, nullptr},
      {"{", code::kParse, nullptr},
      {"{\"cmd\":\"status\"} trailing", code::kParse, nullptr},
      {"[1,2]", code::kBadRequest, nullptr},
      {"\"status\"", code::kBadRequest, nullptr},
      {"{\"id\":3}", code::kBadRequest, 3},
      {"{\"id\":3,\"cmd\":\"\"}", code::kBadRequest, 3},
      {"{\"id\":\"x\",\"cmd\":5}", code::kBadRequest, "x"},
      {"{\"id\":1.5,\"cmd\":\"status\"}", code::kBadRequest, nullptr},
      {"{\"id\":{},\"cmd\":\"status\"}", code::kBadRequest, nullptr},
      {"{\"cmd\":\"st\xff\"}", code::kParse, nullptr},  // invalid UTF-8
  };
  for (const auto& c : cases) {
    auto r = parseRequest(c.line);
    ASSERT_FALSE(r) << c.line;
    EXPECT_EQ(r.error().code, c.code) << c.line;
    EXPECT_EQ(r.error().id, c.id) << c.line;
    EXPECT_FALSE(r.error().message.empty());
  }
}

TEST(Replies, CarryClassAndIdAndEndWithNewline) {
  const std::string line = reply("STATUS", 5, {{"pattern", "grid"}, {"class", "spoofed"}});
  ASSERT_EQ(line.back(), '\n');
  const json j = json::parse(line);
  EXPECT_EQ(j["class"], "STATUS");
  EXPECT_EQ(j["id"], 5);
  EXPECT_EQ(j["pattern"], "grid");

  const json e = json::parse(error("x", code::kTooLarge, "msg \xff"));
  EXPECT_EQ(e["class"], "ERROR");
  EXPECT_EQ(e["id"], "x");
  EXPECT_EQ(e["code"], "too-large");

  const json b = json::parse(versionBanner("1.2.3"));
  EXPECT_EQ(
      b,
      (json{{"class", "VERSION"}, {"release", "1.2.3"}, {"proto_major", 1}, {"proto_minor", 0}}));
}

std::vector<LineFramer::Item> drain(LineFramer& f) {
  std::vector<LineFramer::Item> items;
  LineFramer::Item item;
  while (f.next(item)) items.push_back(item);
  return items;
}

TEST(LineFramer, SplitsAcrossArbitraryChunks) {
  LineFramer f(100);
  const std::string stream = "{\"a\":1}\n{\"b\":2}\r\n\n{\"c\":3}\n";
  for (char ch : stream) f.feed(std::string_view(&ch, 1));
  auto items = drain(f);
  ASSERT_EQ(items.size(), 4u);
  EXPECT_EQ(items[0].line, "{\"a\":1}");
  EXPECT_EQ(items[1].line, "{\"b\":2}");  // \r stripped
  EXPECT_EQ(items[2].line, "");
  EXPECT_EQ(items[3].line, "{\"c\":3}");
}

TEST(LineFramer, OversizedLineReportedOnceThenStreamUsable) {
  LineFramer f(10);
  f.feed(std::string(25, 'x'));  // no newline yet: reported early, buffer freed
  EXPECT_LE(f.buffered(), 10u);
  f.feed(std::string(30, 'y'));
  f.feed("z\nok\n");
  auto items = drain(f);
  ASSERT_EQ(items.size(), 2u);
  EXPECT_TRUE(items[0].oversized);
  EXPECT_FALSE(items[1].oversized);
  EXPECT_EQ(items[1].line, "ok");
}

TEST(LineFramer, LineOfExactlyTheLimitIsAcceptedOneMoreIsNot) {
  LineFramer f(kMaxRequestBytes);
  f.feed(std::string(kMaxRequestBytes, 'a') + "\n" + std::string(kMaxRequestBytes + 1, 'b') + "\n");
  auto items = drain(f);
  ASSERT_EQ(items.size(), 2u);
  EXPECT_FALSE(items[0].oversized);
  EXPECT_EQ(items[0].line.size(), kMaxRequestBytes);
  EXPECT_TRUE(items[1].oversized);
}

}  // namespace
}  // namespace procam::daemon::proto
