// The v4 XML loader: syntax forms, main-tree choice, includes, SubTree remapping and the
// documented load errors.

#include "egress/bt/factory.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.h"

#include "test_nodes.h"

namespace egress::bt {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

class FactoryTest : public ::testing::Test {
 protected:
  FactoryTest() { testing::RegisterTestNodes(factory, &recorder); }

  std::string LoadError(const std::string& xml, const std::string& tree = "",
                        LoadOptions options = {}) {
    try {
      factory.ClearRegisteredTrees();
      factory.RegisterTreesFromText(xml, "test.xml");
      factory.CreateTree(tree, nullptr, options);
    } catch (const LogicError& e) {
      return e.what();
    }
    return "";
  }

  BehaviorTreeFactory factory;
  testing::Recorder recorder;
};

TEST_F(FactoryTest, CompactAndExplicitSyntaxAreEquivalent) {
  Tree compact = factory.CreateTreeFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='A'><Sequence><AlwaysSuccess/><Inverter>"
      "<AlwaysFailure/></Inverter></Sequence></BehaviorTree></root>");
  factory.ClearRegisteredTrees();
  Tree explicit_form = factory.CreateTreeFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='A'><Control ID='Sequence'><Action "
      "ID='AlwaysSuccess'/>"
      "<Decorator ID='Inverter'><Action "
      "ID='AlwaysFailure'/></Decorator></Control></BehaviorTree></root>");
  ASSERT_EQ(compact.nodes().size(), explicit_form.nodes().size());
  for (std::size_t i = 0; i < compact.nodes().size(); ++i) {
    EXPECT_EQ(compact.nodes()[i]->registration_id(), explicit_form.nodes()[i]->registration_id());
    EXPECT_EQ(compact.nodes()[i]->uid(), i + 1);
  }
  EXPECT_EQ(compact.TickOnce(), NodeStatus::kSuccess);
  EXPECT_EQ(explicit_form.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(FactoryTest, ChoosesTheTreeToRun) {
  const std::string two_trees =
      "<root BTCPP_format='4'><BehaviorTree ID='A'><AlwaysSuccess/></BehaviorTree>"
      "<BehaviorTree ID='B'><AlwaysFailure/></BehaviorTree></root>";
  EXPECT_THAT(LoadError(two_trees), HasSubstr("main_tree_to_execute] was not specified"));
  factory.ClearRegisteredTrees();
  factory.RegisterTreesFromText(two_trees);
  EXPECT_EQ(factory.CreateTree("B").TickOnce(), NodeStatus::kFailure);
  factory.ClearRegisteredTrees();
  factory.RegisterTreesFromText(
      "<root BTCPP_format='4' main_tree_to_execute='B'><BehaviorTree "
      "ID='A'><AlwaysSuccess/></BehaviorTree>"
      "<BehaviorTree ID='B'><AlwaysFailure/></BehaviorTree></root>");
  EXPECT_EQ(factory.CreateTree().main_tree_id(), "B");
  EXPECT_EQ(factory.CreateTree("A").main_tree_id(), "A");  // the caller's choice wins
  EXPECT_THAT(LoadError(two_trees, "C"), HasSubstr("no BehaviorTree 'C'"));
}

TEST_F(FactoryTest, WarningsForMissingFormatAndSpacesInIds) {
  factory.CreateTreeFromText(
      "<root><BehaviorTree ID='Move to Pose (JTC)'><AlwaysSuccess/></BehaviorTree></root>");
  ASSERT_EQ(factory.warnings().size(), 2u);
  EXPECT_THAT(factory.warnings()[0], HasSubstr("no BTCPP_format"));
  EXPECT_THAT(factory.warnings()[1], HasSubstr("contains spaces"));
  EXPECT_THAT(
      LoadError(
          "<root BTCPP_format='3'><BehaviorTree ID='A'><AlwaysSuccess/></BehaviorTree></root>"),
      HasSubstr("BTCPP_format=\"3\" is not supported"));
}

TEST_F(FactoryTest, ErrorsNameFileLineElementAndProblem) {
  EXPECT_THAT(
      LoadError(
          "<root BTCPP_format='4'>\n<BehaviorTree ID='A'>\n<Sequence>\n</BehaviorTree></root>"),
      StartsWith("test.xml:3: malformed XML"));
  EXPECT_THAT(LoadError("<tree/>"), HasSubstr("must be <root>"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'>\n<Sequence>\n<Wait/></Sequence>"
                "</BehaviorTree></root>"),
      StartsWith("test.xml:3: unknown node type 'Wait' in BehaviorTree 'A'"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><inverter><AlwaysSuccess/></inverter>"
                "</BehaviorTree></root>"),
      HasSubstr("did you mean 'Inverter'?"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Repeat><AlwaysSuccess/></Repeat>"
                "</BehaviorTree></root>"),
      HasSubstr("node 'Repeat': missing required port 'num_cycles'"));
  EXPECT_THAT(LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Sleep msec='10' sec='1'/>"
                        "</BehaviorTree></root>"),
              HasSubstr("port 'sec' is not declared by 'Sleep' (its ports: msec)"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Sleep name='nap' msec='soon'/>"
                "</BehaviorTree></root>"),
      HasSubstr(
          "node 'nap' (Sleep): port 'msec' value 'soon' cannot be converted to unsigned int"));
  EXPECT_THAT(
      LoadError(
          "<root BTCPP_format='4'><BehaviorTree ID='A'><Inverter><AlwaysSuccess/><AlwaysSuccess/>"
          "</Inverter></BehaviorTree></root>"),
      HasSubstr("has 2 children; a Decorator has exactly one"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Sequence/></BehaviorTree></root>"),
      HasSubstr("a Control has at least one"));
  EXPECT_THAT(LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><IfThenElse><AlwaysSuccess/>"
                        "</IfThenElse></BehaviorTree></root>"),
              HasSubstr("it takes 2 or 3"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Switch2 variable='x'><AlwaysSuccess/>"
                "</Switch2></BehaviorTree></root>"),
      HasSubstr("Switch2 takes 3"));
  EXPECT_THAT(LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Script code='x := (1'/>"
                        "</BehaviorTree></root>"),
              HasSubstr("port 'code': invalid script 'x := (1'"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><AlwaysSuccess _skipIf='a ==='/>"
                "</BehaviorTree></root>"),
      HasSubstr("_skipIf: invalid script"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Action/></BehaviorTree></root>"),
      HasSubstr("<Action> needs an ID attribute"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Sequence ID='x'><AlwaysSuccess/>"
                "</Sequence></BehaviorTree></root>"),
      HasSubstr("must not have an ID attribute"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><AlwaysSuccess/><AlwaysSuccess/>"
                "</BehaviorTree></root>"),
      HasSubstr("exactly one root node"));
  EXPECT_THAT(LoadError("<root BTCPP_format='4'><TreeNodesModel/><TreeNodesModel/></root>"),
              HasSubstr("a second <TreeNodesModel>"));
}

TEST_F(FactoryTest, BlackboardTypeMismatchesFailAtLoad) {
  factory.RegisterSimpleAction("SetSpeed", [](TreeNode&) { return NodeStatus::kSuccess; },
                               {InputPort<double>("speed")});
  const std::string message = LoadError(
      "<root BTCPP_format='4'><BehaviorTree ID='A'><Sequence><Counter key='{v}'/>"
      "<SetSpeed name='slow' speed='{v}'/></Sequence></BehaviorTree></root>");
  EXPECT_THAT(message, HasSubstr("node 'slow' (SetSpeed): port 'speed'"));
  EXPECT_THAT(message, HasSubstr("first used with type int and now with type double"));
}

TEST_F(FactoryTest, UnderscoreAttributesAreIgnored) {
  Tree tree = factory.CreateTreeFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='A' _description='x' _favorite='true'>"
      "<Sequence _collapsed='true' _uid='7'><AlwaysSuccess "
      "_hardcoded='1'/></Sequence></BehaviorTree></root>");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
}

TEST_F(FactoryTest, SubTreeRemappingLiteralsAndAutoremap) {
  auto board = Blackboard::Create();
  board->Set("door", 3);
  Tree tree = factory.CreateTreeFromText(
      "<root BTCPP_format='4'>"
      " <BehaviorTree ID='Main'><Sequence>"
      "  <SubTree ID='Open' name='first' target='{door}' attempts='2' same='{=}'/>"
      "  <SubTree ID='Auto' _autoremap='true'/>"
      " </Sequence></BehaviorTree>"
      " <BehaviorTree ID='Open'><Script code='target += attempts; result := target; _tmp := "
      "1'/></BehaviorTree>"
      " <BehaviorTree ID='Auto'><Script code=\"shared := 'up'; _private := 1\"/></BehaviorTree>"
      "</root>",
      "Main", board);
  board->Set("same", 1);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_EQ(board->Get<int>("door"), 5);               // remapped read and write
  EXPECT_FALSE(board->Has("result"));                  // isolated scope
  EXPECT_EQ(board->Get<std::string>("shared"), "up");  // autoremap
  EXPECT_FALSE(board->Has("_private"));                // private keys never autoremap
  // Paths name the instances.
  EXPECT_NE(tree.FindNode("first"), nullptr);
  EXPECT_EQ(tree.FindNode("first")->kind(), NodeKind::kSubTree);
}

TEST_F(FactoryTest, NestedSubTreesRemapThroughEveryLevel) {
  auto board = Blackboard::Create();
  board->Set("count", 0);
  Tree tree = factory.CreateTreeFromText(
      "<root BTCPP_format='4'>"
      " <BehaviorTree ID='Main'><SubTree ID='Mid' n='{count}'/></BehaviorTree>"
      " <BehaviorTree ID='Mid'><Sequence><SubTree ID='Leaf' name='a' k='{n}'/>"
      "   <SubTree ID='Leaf' name='b' k='{n}'/></Sequence></BehaviorTree>"
      " <BehaviorTree ID='Leaf'><Counter key='{k}'/></BehaviorTree>"
      "</root>",
      "Main", board);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_EQ(board->Get<int>("count"), 2);
  EXPECT_NE(tree.FindNode("Mid::1/a"), nullptr);
  EXPECT_NE(tree.FindNode("Mid::1/b/Counter::6"), nullptr);
}

TEST_F(FactoryTest, SubTreeModelsGiveDefaultsAndRequirePorts) {
  const std::string model =
      "<TreeNodesModel><SubTree ID='Check'><input_port name='expected' default='1'/>"
      "<inout_port name='value' default='{vector}'/><input_port "
      "name='must'/></SubTree></TreeNodesModel>";
  const std::string body =
      "<BehaviorTree ID='Check'><ScriptCondition code='value == expected'/></BehaviorTree>";
  EXPECT_THAT(
      LoadError(
          "<root BTCPP_format='4'><BehaviorTree ID='Main'><SubTree ID='Check'/></BehaviorTree>" +
              body + model + "</root>",
          "Main"),
      HasSubstr("port 'must' is declared in its TreeNodesModel without a default"));
  auto board = Blackboard::Create();
  board->Set("vector", 1);
  factory.ClearRegisteredTrees();
  Tree tree = factory.CreateTreeFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='Main'><SubTree ID='Check' "
      "must='x'/></BehaviorTree>" +
          body + model + "</root>",
      "Main", board);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);  // expected=1 (default), value -> {vector}=1
}

TEST_F(FactoryTest, AMainTreeGetsItsModelsLiteralDefaultsWhereItsBlackboardHasNoEntry) {
  // The same tree run on its own: its optional ports take the model's defaults (as a SubTree
  // call's do: numbers parsed, the rest text that typed ports convert), an entry the caller set
  // wins, and a default naming an entry ({key}) is left alone (no parent to read it from).
  const std::string xml =
      "<root BTCPP_format='4'><BehaviorTree ID='Check'><ScriptCondition code='speed == "
      "expected'/></BehaviorTree><TreeNodesModel><SubTree ID='Check'><input_port "
      "name='fast' default='false'/><input_port name='speed' default='2'/><input_port "
      "name='expected'/><input_port name='other' default='{elsewhere}'/></SubTree>"
      "</TreeNodesModel></root>";
  auto board = Blackboard::Create();
  board->Set("expected", 2);
  Tree tree = factory.CreateTreeFromText(xml, "Check", board);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_EQ(board->Get<std::string>("fast"), "false");
  EXPECT_FALSE(board->Has("other"));
  factory.ClearRegisteredTrees();
  auto given = Blackboard::Create();
  given->Set("expected", 3);
  given->Set("speed", 3);
  given->Set("fast", true);
  Tree fast = factory.CreateTreeFromText(xml, "Check", given);
  EXPECT_EQ(fast.TickOnce(), NodeStatus::kSuccess);
  EXPECT_TRUE(given->Get<bool>("fast"));
  factory.ClearRegisteredTrees();
  auto other = Blackboard::Create();
  other->Set("expected", 3);  // speed defaults to 2: the condition fails
  Tree slow = factory.CreateTreeFromText(xml, "Check", other);
  EXPECT_EQ(slow.TickOnce(), NodeStatus::kFailure);
}

TEST_F(FactoryTest, RecursionDuplicatesAndMissingSubTrees) {
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><SubTree ID='B'/></BehaviorTree>"
                "<BehaviorTree ID='B'><SubTree ID='A'/></BehaviorTree></root>",
                "A"),
      HasSubstr("recursive SubTree: A -> B -> A"));
  EXPECT_THAT(
      LoadError("<root BTCPP_format='4'><BehaviorTree ID='A'><Sequence><SubTree ID='B' name='x'/>"
                "<SubTree ID='B' name='x'/></Sequence></BehaviorTree><BehaviorTree ID='B'>"
                "<AlwaysSuccess/></BehaviorTree></root>",
                "A"),
      HasSubstr("Duplicate SubTree path 'x'"));
  const std::string missing =
      "<root BTCPP_format='4'><BehaviorTree ID='A'><SubTree ID='Open "
      "Gripper'/></BehaviorTree></root>";
  EXPECT_THAT(LoadError(missing), HasSubstr("SubTree 'Open Gripper' is not defined"));
  factory.ClearRegisteredTrees();
  Tree stubbed = factory.CreateTreeFromText(missing, "", nullptr, {false, true});
  EXPECT_EQ(stubbed.stubbed_subtree_ids(), std::vector<std::string>{"Open Gripper"});
  EXPECT_EQ(stubbed.TickOnce(), NodeStatus::kSuccess);
  EXPECT_THAT(LoadError("<root BTCPP_format='4'><BehaviorTree "
                        "ID='Sequence'><AlwaysSuccess/></BehaviorTree></root>"),
              HasSubstr("is the name of a registered node type"));
}

TEST_F(FactoryTest, StandInsForUnknownNodes) {
  const std::string xml =
      "<root BTCPP_format='4'><BehaviorTree ID='A'><PipelineSequence><GoalUpdated/>"
      "<RateController hz='1'><ComputePath "
      "goal='{goal}'/></RateController></PipelineSequence></BehaviorTree></root>";
  Tree tree = factory.CreateTreeFromText(xml, "", nullptr, {true, false});
  EXPECT_EQ(tree.stand_in_node_ids(), (std::vector<std::string>{"PipelineSequence", "GoalUpdated",
                                                                "RateController", "ComputePath"}));
  EXPECT_EQ(tree.nodes()[0]->kind(), NodeKind::kControl);
  EXPECT_EQ(tree.nodes()[2]->kind(), NodeKind::kDecorator);
  tree.SetStandInDriver([](const TreeNode& node) {
    return node.name() == "ComputePath" ? NodeStatus::kRunning : NodeStatus::kSuccess;
  });
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  EXPECT_EQ(tree.FindNodesByName("ComputePath").front()->GetInput<std::string>("goal").has_value(),
            false);
}

TEST_F(FactoryTest, IncludesResolveRelativeToTheIncludingFile) {
  const auto dir = egress::testing::TestTempPath("include");
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "main.xml")
      << "<root BTCPP_format='4'><include path='sub/child.xml'/>"
         "<BehaviorTree ID='Main'><SubTree ID='Child'/></BehaviorTree></root>";
  std::ofstream(dir / "sub" / "child.xml")
      << "<root BTCPP_format='4'><include path='grand.xml'/>"
         "<BehaviorTree ID='Child'><SubTree ID='Grand'/></BehaviorTree></root>";
  std::ofstream(dir / "sub" / "grand.xml") << "<root BTCPP_format='4'><BehaviorTree ID='Grand'>"
                                              "<AlwaysSuccess/></BehaviorTree></root>";
  Tree tree = factory.CreateTreeFromFile(dir / "main.xml", "Main");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);

  std::ofstream(dir / "loop.xml") << "<root BTCPP_format='4'><include path='loop.xml'/></root>";
  factory.ClearRegisteredTrees();
  EXPECT_THROW(factory.RegisterTreesFromFile(dir / "loop.xml"), LogicError);
  EXPECT_THROW(factory.RegisterTreesFromFile(dir / "absent.xml"), LogicError);
  std::filesystem::remove_all(dir);
}

// Found by probing (kept as a regression test): an <include> of a device read without end.
// Only regular files are read, and only up to the size cap.
TEST_F(FactoryTest, IncludesOfDevicesOrHugeFilesAreRefused) {
  const auto dir = egress::testing::TestTempPath("include_special");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "zero.xml")
      << "<root BTCPP_format='4'><include path='/dev/zero'/>"
         "<BehaviorTree ID='Main'><AlwaysSuccess/></BehaviorTree></root>";
  EXPECT_THAT([&] { factory.RegisterTreesFromFile(dir / "zero.xml"); },
              ::testing::ThrowsMessage<LogicError>(::testing::AllOf(
                  HasSubstr("zero.xml:1"), HasSubstr("'/dev/zero' is not a regular file"))));
  EXPECT_THAT([&] { factory.RegisterTreesFromFile("/dev/zero"); },
              ::testing::ThrowsMessage<LogicError>(HasSubstr("not a regular file")));
  {
    std::ofstream huge(dir / "huge.xml");
    const std::string block(1 << 20, ' ');
    for (int i = 0; i < 17; ++i)
      huge << block;
  }
  EXPECT_THAT([&] { factory.RegisterTreesFromFile(dir / "huge.xml"); },
              ::testing::ThrowsMessage<LogicError>(HasSubstr("is larger than")));
  std::filesystem::remove_all(dir);
}

struct Pose2 {
  double x, y, yaw;
};

TEST_F(FactoryTest, UserTypesWithRegisteredConverters) {
  factory.RegisterConverter<Pose2>([](std::string_view text) {
    const auto parts = SplitSemicolons(text);
    if (parts.size() != 3) throw RuntimeError("a Pose2 is 'x;y;yaw'");
    return Pose2{ParseReal(parts[0]), ParseReal(parts[1]), ParseReal(parts[2])};
  });
  double seen_x = 0.0;
  factory.RegisterSimpleAction("GoTo",
                               [&](TreeNode& node) {
                                 seen_x = node.GetInput<Pose2>("goal").value().x;
                                 return NodeStatus::kSuccess;
                               },
                               {InputPort<Pose2>("goal")});
  Tree tree = factory.CreateTreeFromText(
      "<root BTCPP_format='4'><BehaviorTree ID='A'><GoTo goal='1.5;2;0'/></BehaviorTree></root>");
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  EXPECT_DOUBLE_EQ(seen_x, 1.5);
  EXPECT_THAT(
      LoadError(
          "<root BTCPP_format='4'><BehaviorTree ID='A'><GoTo goal='1;2'/></BehaviorTree></root>"),
      HasSubstr(
          "cannot be converted to egress::bt::(anonymous namespace)::Pose2: a Pose2 is 'x;y;yaw'"));
}

TEST_F(FactoryTest, RegistrationRules) {
  EXPECT_THROW(
      factory.RegisterSimpleAction("Sequence", [](TreeNode&) { return NodeStatus::kSuccess; }),
      LogicError);
  EXPECT_THROW(
      factory.RegisterSimpleAction("Bad Name", [](TreeNode&) { return NodeStatus::kSuccess; }),
      LogicError);
  EXPECT_THROW(factory.RegisterSimpleAction("X", [](TreeNode&) { return NodeStatus::kSuccess; },
                                            {InputPort<int>("1st")}),
               LogicError);
}

TEST_F(FactoryTest, ExportsTheTreeNodesModel) {
  factory.RegisterSimpleAction("PressButton", [](TreeNode&) { return NodeStatus::kSuccess; },
                               {InputPort<double>("stroke", 0.004, "button travel [m]"),
                                OutputPort<bool>("pressed", "whether the press registered")});
  const std::string xml = factory.WriteTreeNodesModelXml();
  EXPECT_THAT(xml, HasSubstr("<Action ID=\"PressButton\">"));
  EXPECT_THAT(
      xml,
      HasSubstr("<input_port name=\"stroke\" type=\"double\" default=\"0.004\">button travel [m]"));
  EXPECT_THAT(xml, HasSubstr("<output_port name=\"pressed\" type=\"bool\">"));
  EXPECT_THAT(xml, ::testing::Not(HasSubstr("\"Sequence\"")));
  EXPECT_THAT(factory.WriteTreeNodesModelXml(true), HasSubstr("<Control ID=\"Sequence\"/>"));
  // The export reads back as stand-ins in another factory.
  BehaviorTreeFactory other;
  const auto ids = other.RegisterStandInsFromModelText(xml, "model.xml");
  EXPECT_THAT(ids, ::testing::Contains("PressButton"));
  EXPECT_EQ(other.FindManifest("PressButton")->ports.at("stroke").default_value, "0.004");
}

}  // namespace
}  // namespace egress::bt
