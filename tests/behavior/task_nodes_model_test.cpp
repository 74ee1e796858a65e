// The shipped TreeNodesModel (behavior/trees/egress_nodes.xml, what Groot2 and `egress bt trace
// --model` read) says exactly what the registered task nodes provide: same nodes, kinds, ports,
// types and defaults. Both go through the factory's writer, so comments and layout do not count.

#include <gtest/gtest.h>

#include "egress/behavior/task_nodes.h"
#include "egress/bt/factory.h"

namespace egress::behavior {
namespace {

TEST(TaskNodesModelTest, TheShippedModelMatchesTheRegistrations) {
  const std::string generated = TaskNodesModelXml();
  bt::BehaviorTreeFactory shipped;
  const auto ids =
      shipped.RegisterStandInsFromModelFile(std::string(EGRESS_TREES_DIR) + "/egress_nodes.xml");
  EXPECT_FALSE(ids.empty());
  EXPECT_EQ(shipped.WriteTreeNodesModelXml(false), generated)
      << "regenerate with: egress bt model --out behavior/trees/egress_nodes.xml --overwrite";
  for (const char* id :
       {"NavigateTo", "TraverseDoor", "PlanGrasp", "CloseGripper", "WithdrawArm", "IsPathClear"})
    EXPECT_NE(generated.find(std::string("ID=\"") + id + "\""), std::string::npos) << id;
}

}  // namespace
}  // namespace egress::behavior
