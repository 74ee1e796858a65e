#include "egress/bt/blackboard.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace egress::bt {
namespace {

using ::testing::HasSubstr;

TEST(BlackboardTest, TypedValuesConvert) {
  auto board = Blackboard::Create();
  board->Set("n", 7);
  EXPECT_EQ(board->Get<int>("n"), 7);
  EXPECT_EQ(board->Get<double>("n"), 7.0);
  EXPECT_EQ(board->Get<std::string>("n"), "7");
  board->Set("text", std::string("12"));
  EXPECT_EQ(board->Get<int>("text"), 12);  // strings convert on read
  board->Set("half", 0.5);
  EXPECT_THROW(board->Get<int>("half"), RuntimeError);  // not an integer
  EXPECT_FALSE(board->Get<int>("absent").has_value());
  EXPECT_EQ(board->SequenceId("n"), 1u);
  board->Set("n", 8);
  EXPECT_EQ(board->SequenceId("n"), 2u);
}

TEST(BlackboardTest, RemapsReachTheParent) {
  auto parent = Blackboard::Create();
  auto child = Blackboard::Create(parent);
  child->AddRemap("goal", "door_goal");
  child->Set("goal", 3);
  EXPECT_EQ(parent->Get<int>("door_goal"), 3);
  EXPECT_FALSE(parent->Has("goal"));
  child->Set("local", 1);
  EXPECT_FALSE(parent->Has("local"));  // isolated by default
  EXPECT_TRUE(child->Unset("goal"));
  EXPECT_FALSE(parent->Has("door_goal"));
}

TEST(BlackboardTest, AutoRemapSkipsPrivateKeys) {
  auto parent = Blackboard::Create();
  auto child = Blackboard::Create(parent);
  child->SetAutoRemap(true);
  child->Set("shared", 1);
  child->Set("_private", 2);
  EXPECT_EQ(parent->Get<int>("shared"), 1);
  EXPECT_FALSE(parent->Has("_private"));
  EXPECT_EQ(child->Get<int>("_private"), 2);
}

TEST(BlackboardTest, RootKeysFromDeepScopes) {
  auto root = Blackboard::Create();
  auto mid = Blackboard::Create(root);
  auto leaf = Blackboard::Create(mid);
  leaf->Set("@alarm", true);
  EXPECT_EQ(root->Get<bool>("alarm"), true);
  EXPECT_EQ(leaf->Get<bool>("@alarm"), true);
  EXPECT_FALSE(leaf->Has("alarm"));
}

TEST(BlackboardTest, DeclaredTypesAreEnforced) {
  auto board = Blackboard::Create();
  auto int_port = InputPort<int>("count").second;
  auto double_port = InputPort<double>("speed").second;
  board->DeclareType("x", int_port);
  board->DeclareType("x", InputPort<long>("y").second);  // same storage: compatible
  try {
    board->DeclareType("x", double_port);
    FAIL() << "expected LogicError";
  } catch (const LogicError& e) {
    EXPECT_THAT(e.what(), HasSubstr("first used with type int"));
    EXPECT_THAT(e.what(), HasSubstr("now with type double"));
  }
  board->Set("x", std::string("42"));  // parsed with the port's converter
  EXPECT_TRUE(board->GetAny("x")->IsType<std::int64_t>());
  EXPECT_THROW(board->Set("x", std::string("forty")), RuntimeError);
  board->DeclareType("s", InputPort<std::string>("s").second);  // strings are not strongly typed
  board->Set("s", 5);
}

}  // namespace
}  // namespace egress::bt
