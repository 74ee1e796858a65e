#pragma once
/// @file
/// The parsers egress exposes to files and clients, as fuzz entry points: each takes arbitrary
/// bytes and must either accept them or throw egress's documented error, never crash, hang or
/// leak. `egress_fuzz_<name>` (clang, libFuzzer, ASan + UBSan: `./egress.sh fuzz`) calls one;
/// the regression test runs every kept input (fuzz/regressions/<name>/) through the same
/// function in the ordinary build.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace egress::fuzz {

using FuzzTarget = int (*)(const std::uint8_t* data, std::size_t size);

struct NamedTarget {
  std::string_view name;
  FuzzTarget run;
};

/// A BehaviorTree.CPP script (`<Script code=...>`): parsed, then evaluated on a blackboard.
int BtScript(const std::uint8_t* data, std::size_t size);
/// A behavior tree XML document: loaded with the built-in nodes, its main tree created and
/// ticked a few times (unknown leaves registered as stand-ins first).
int BtXml(const std::uint8_t* data, std::size_t size);
/// A scenario YAML document (its world resolved against worlds/lab).
int ScenarioYaml(const std::uint8_t* data, std::size_t size);
/// An SDF world document.
int SdfWorld(const std::uint8_t* data, std::size_t size);
/// A URDF robot model.
int Urdf(const std::uint8_t* data, std::size_t size);
/// A map_server map: the bytes up to the first NUL are the YAML, the rest the image file it
/// names (`map.pgm`), read confined to a scratch directory (ScopedReadRoot) with a 1 M cell cap.
int MapServer(const std::uint8_t* data, std::size_t size);
/// egress-navd's request handlers (NavigationHandlers) on a fresh service: a sequence of
/// calls, each [RPC index byte][length: 2 bytes, little-endian][serialized request].
int NavdRequests(const std::uint8_t* data, std::size_t size);

/// Every target, by the name its corpus and regression folders use.
const std::vector<NamedTarget>& AllTargets();

}  // namespace egress::fuzz
