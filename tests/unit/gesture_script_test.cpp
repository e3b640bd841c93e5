// The headless client's gesture script: each kind of event read as written, each mistake named
// with the event it is in, and the default drag's shape.
#include "gesture_script.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace fluidcast::client {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_gesture_script(text, "script.json");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(GestureScript, EachKindOfEventIsReadAsWritten) {
  const std::vector<ScriptedEvent> events = parse_gesture_script(R"({"events": [
      {"t": 0.5, "pointer": {"id": 3, "phase": "down", "x": 0.25, "y": 0.75}},
      {"t": 0.6, "pointer": {"phase": "move", "x": 0.3, "y": 0.7}},
      {"t": 0.7, "pointer": {"phase": "up", "x": 0.3, "y": 0.7}},
      {"t": 0.8, "pointer": {"phase": "cancel", "x": 0.3, "y": 0.7}},
      {"t": 1.5, "tilt": [3.0, -9.3, 0.5]},
      {"t": 2.0, "command": "reset"},
      {"t": 2.5, "command": "pause"},
      {"t": 3.0, "command": "resume"}]})",
                                                                 "script.json");
  ASSERT_EQ(events.size(), 8u);
  EXPECT_DOUBLE_EQ(events[0].time, 0.5);
  const v1::PointerEvent& down = events[0].message.pointer();
  EXPECT_EQ(down.pointer_id(), 3u);
  EXPECT_EQ(down.phase(), v1::PointerEvent::DOWN);
  EXPECT_FLOAT_EQ(down.x(), 0.25f);
  EXPECT_FLOAT_EQ(down.y(), 0.75f);
  EXPECT_EQ(events[1].message.pointer().pointer_id(), 0u);  // the first finger unless named
  EXPECT_EQ(events[1].message.pointer().phase(), v1::PointerEvent::MOVE);
  EXPECT_EQ(events[2].message.pointer().phase(), v1::PointerEvent::UP);
  EXPECT_EQ(events[3].message.pointer().phase(), v1::PointerEvent::CANCEL);
  const v1::Tilt& tilt = events[4].message.tilt();
  EXPECT_FLOAT_EQ(tilt.x(), 3.0f);
  EXPECT_FLOAT_EQ(tilt.y(), -9.3f);
  EXPECT_FLOAT_EQ(tilt.z(), 0.5f);
  EXPECT_TRUE(events[5].message.command().reset());
  ASSERT_TRUE(events[6].message.command().has_pause());
  EXPECT_TRUE(events[6].message.command().pause());
  ASSERT_TRUE(events[7].message.command().has_pause());
  EXPECT_FALSE(events[7].message.command().pause());
}

TEST(GestureScript, EachMistakeIsNamedWithItsEvent) {
  EXPECT_TRUE(error_of("{").starts_with("script.json: not JSON")) << error_of("{");
  EXPECT_EQ(error_of(R"({"moves": []})"), R"(script.json: needs an object with an array "events")");
  EXPECT_EQ(error_of(R"({"events": {}})"),
            R"(script.json: needs an object with an array "events")");
  const std::string ok = R"({"t": 0, "command": "reset"}, )";
  EXPECT_EQ(error_of(R"({"events": [)" + ok + R"({"t": 1}]})"),
            "script.json: event 1: needs a pointer, tilt or command");
  EXPECT_EQ(error_of(R"({"events": [)" + ok +
                     R"({"t": 1, "pointer": {"phase": "hover", "x": 0, "y": 0}}]})"),
            "script.json: event 1: phase 'hover' is not down, move, up or cancel");
  EXPECT_EQ(error_of(R"({"events": [{"t": 1, "command": "explode"}]})"),
            "script.json: event 0: command 'explode' is not reset, pause or resume");
  for (const char* bad :
       {R"({"events": [{"command": "reset"}]})", R"({"events": [{"t": 1, "tilt": [1, 2]}]})",
        R"({"events": [{"t": 1, "pointer": {"phase": "down", "x": 0.5}}]})",
        R"({"events": [{"t": "soon", "command": "reset"}]})"}) {
    EXPECT_TRUE(error_of(bad).starts_with("script.json: event 0: "))
        << bad << ": " << error_of(bad);
  }
  try {
    read_gesture_script("/nonexistent/script.json");
    ADD_FAILURE() << "read a script that is not there";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "--script /nonexistent/script.json: cannot open it");
  }
}

// Down at 0.2 s, a move every thirtieth of a second across the middle, up 0.2 s before the end
// (never before 0.3 s). 2.05 s: the last move falls well clear of the lift, at 1.833 s.
TEST(GestureScript, TheDefaultDragCrossesTheMiddleAndLifts) {
  const std::vector<ScriptedEvent> drag = default_gesture(2.05);
  ASSERT_GE(drag.size(), 3u);
  EXPECT_EQ(drag.front().message.pointer().phase(), v1::PointerEvent::DOWN);
  EXPECT_DOUBLE_EQ(drag.front().time, 0.2);
  EXPECT_EQ(drag.back().message.pointer().phase(), v1::PointerEvent::UP);
  EXPECT_DOUBLE_EQ(drag.back().time, 2.05 - 0.2);
  EXPECT_EQ(drag.size(), 2u + 49u);  // moves from 0.2 + 1/30 s to before 1.85 s
  float least = 1.0f, most = 0.0f;
  for (std::size_t k = 1; k + 1 < drag.size(); ++k) {
    const v1::PointerEvent& move = drag[k].message.pointer();
    EXPECT_EQ(move.phase(), v1::PointerEvent::MOVE);
    EXPECT_NEAR(drag[k].time - drag[k - 1].time, 1.0 / 30.0, 1e-9);
    least = std::min(least, move.x());
    most = std::max(most, move.x());
    EXPECT_FLOAT_EQ(move.y(), 0.6f);
  }
  EXPECT_LT(least, 0.25f);
  EXPECT_GT(most, 0.75f);
  EXPECT_DOUBLE_EQ(default_gesture(0.1).back().time, 0.3);
}

}  // namespace
}  // namespace fluidcast::client
