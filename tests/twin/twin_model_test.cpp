#include "egress/twin/twin_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/twin/trace.h"
#include "egress/twin/twin_world.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using testing::Hsr;
using testing::WorldsDir;

// The trace hash of 8 s of a run (the base driving a slow arc through the office's people).
std::uint64_t TraceHash(TwinWorld& world) {
  TraceRecorder trace;
  while (world.time() < 8.0) {
    world.SetBaseVelocity({0.3, 0.0, 0.1});
    world.Step();
    trace.Observe(world);
  }
  return trace.Hash();
}

class TwinModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scenario_ = LoadScenario(WorldsDir() / "office/office_evacuation.yaml");
    world_ = LoadSdfWorld(scenario_.world_file);
  }
  Scenario scenario_;
  WorldDescription world_;
};

TEST_F(TwinModelTest, RunsSharingOneModelAreTheRunsOfTheirOwnModels) {
  auto model = std::make_shared<const TwinModel>(scenario_, world_, Hsr());
  // Two runs alive on one model: a run's state is its own, the model is only read.
  TwinWorld a(model, 5), b(model, 6);
  const std::uint64_t hash_a = TraceHash(a), hash_b = TraceHash(b);
  TwinWorld own_a(scenario_, world_, 5, Hsr()), own_b(scenario_, world_, 6, Hsr());
  EXPECT_EQ(hash_a, TraceHash(own_a));
  EXPECT_EQ(hash_b, TraceHash(own_b));
  EXPECT_NE(hash_a, hash_b);
  // And again after both ran: nothing of a run stayed in the model.
  TwinWorld again(model, 5);
  EXPECT_EQ(hash_a, TraceHash(again));
  EXPECT_EQ(a.model().get(), model.get());
}

TEST_F(TwinModelTest, TheModelOutlivesWhoeverBuiltIt) {
  std::unique_ptr<TwinWorld> run;
  {
    auto model = std::make_shared<const TwinModel>(scenario_, world_, Hsr());
    run = std::make_unique<TwinWorld>(model, 3);
  }
  run->StepFor(1.0);  // the run keeps its model (statics' shapes, door geometry) alive
  EXPECT_EQ(run->door_count(), world_.doors.size());
  EXPECT_GT(run->time(), 0.99);
}

TEST_F(TwinModelTest, ANullModelOrRobotIsAnError) {
  EXPECT_THROW(TwinWorld(std::shared_ptr<const TwinModel>(), 1), InvalidArgument);
  EXPECT_THROW(TwinModel(scenario_, world_, nullptr), InvalidArgument);
}

TEST_F(TwinModelTest, ABadConfigNamesTheField) {
  TwinConfig config;
  config.physics_rate_hz = 30.0;
  EXPECT_THAT([&] { TwinModel(scenario_, world_, Hsr(), config); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("physics_rate_hz")));
  config = {};
  config.crowd_social_rate_hz = 480.0;  // above the physics rate
  EXPECT_THAT(
      [&] { TwinModel(scenario_, world_, Hsr(), config); },
      ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("crowd_social_rate_hz")));
  for (const double crowd_rate : {100.0, 480.0, 0.0, std::nan("")}) {  // 240 / k only
    config = {};
    config.crowd_rate_hz = crowd_rate;
    config.crowd_social_rate_hz = 60.0;
    EXPECT_THAT([&] { TwinModel(scenario_, world_, Hsr(), config); },
                ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("crowd_rate_hz")))
        << crowd_rate;
  }
  config = {};
  config.crowd_rate_hz = 60.0;  // the social terms at most as often as the rest
  EXPECT_THAT(
      [&] { TwinModel(scenario_, world_, Hsr(), config); },
      ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("crowd_social_rate_hz")));
  config.crowd_social_rate_hz = 60.0;
  EXPECT_NO_THROW(TwinModel(scenario_, world_, Hsr(), config));
  config = {};
  config.robot_mass = std::nan("");
  EXPECT_THAT([&] { TwinModel(scenario_, world_, Hsr(), config); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("robot_mass")));
  config = {};
  config.base_command_timeout = -1.0;
  EXPECT_THAT(
      [&] { TwinModel(scenario_, world_, Hsr(), config); },
      ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("base_command_timeout")));
}

TEST_F(TwinModelTest, AScenarioThatDoesNotFitItsWorldFailsToCompile) {
  scenario_.doors.push_back({});
  scenario_.doors.back().door = "no_such_door";
  EXPECT_THROW(TwinModel(scenario_, world_, Hsr()), LoadError);
}

}  // namespace
}  // namespace egress::twin
