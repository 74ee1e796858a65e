#!/usr/bin/env bash
# Writes the binary seeds and kept inputs of the map_server and navd_requests fuzz targets from
# the project's own files and readable request texts (protoc --encode), so that they can be
# reviewed and regenerated: fuzz/make_seeds.sh (needs protoc; run from anywhere).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
proto_dir=$root/api
proto=egress/nav/v1/navigation.proto

# map_server: YAML, NUL, image bytes (the target writes the image as map.pgm).
map() {  # map OUT YAML IMAGE_FILE
  { printf '%s' "$2"; printf '\0'; cat "$3"; } > "$1"
}
office=$root/worlds/office/office.pgm
map "$root/fuzz/seeds/map_server/office" $'image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n' "$office"
map "$root/fuzz/seeds/map_server/negated" $'image: map.pgm\nresolution: 0.1\norigin: [-2, 3.5, 0]\nnegate: 1\nmode: trinary\n' "$office"
# Kept: an image outside the scratch root; a PGM header claiming 2^31 x 2^31 cells.
map "$root/fuzz/regressions/map_server/image_outside_root" $'image: /etc/hostname\nresolution: 0.05\norigin: [0, 0, 0]\n' /dev/null
{ printf 'image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n\0'; printf 'P5\n2147483647 2147483647\n255\n'; } \
  > "$root/fuzz/regressions/map_server/huge_pgm_header"

# navd_requests: frames [RPC index][length, 2 bytes LE][request], RPC indices as in
# NavigationHandlers::Rpcs(): 0 LoadWorld, 1 UpdateCostmap, 2 UnloadWorld, 3 SetDoorState,
# 4 PlanPath, 5 ListPlanners, 6 Health.
frame() {  # frame RPC_INDEX MESSAGE_TYPE TEXT
  local bytes
  bytes=$(mktemp)
  printf '%s' "$3" | protoc --encode="egress.nav.v1.$2" -I "$proto_dir" "$proto" > "$bytes"
  local n
  n=$(stat -c %s "$bytes")
  [ "$n" -lt 65536 ] || { echo "request too long for a frame" >&2; exit 1; }
  printf "\\x$(printf %02x "$1")\\x$(printf %02x $((n & 255)))\\x$(printf %02x $((n >> 8)))"
  cat "$bytes"
  rm -f "$bytes"
}
small_map='map { image: "P5\n8 8\n255\n\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377\377" resolution: 0.1 }'
seeds=$root/fuzz/seeds/navd_requests
{
  frame 0 LoadWorldRequest "$small_map doors { id: \"d\" hinge { x: 0.3 y: 0.1 } latch { x: 0.3 y: 0.7 } }"
  frame 3 SetDoorStateRequest 'world_id: "world-1" door_id: "d" angle: 1.2'
  frame 1 UpdateCostmapRequest 'world_id: "world-1" scan { laser_pose { x: 0.2 y: 0.4 } angle_min: -1 angle_increment: 0.5 range_min: 0.05 range_max: 5 ranges: [0.3, 0.4, inf, nan, 0.5] }'
  frame 4 PlanPathRequest 'world_id: "world-1" start { x: 0.15 y: 0.15 } goal { x: 0.65 y: 0.65 } time_budget: 0.02'
  frame 1 UpdateCostmapRequest 'world_id: "world-1" obstacles { points { x: 0.4 y: 0.4 } }'
  frame 2 UnloadWorldRequest 'world_id: "world-1"'
  frame 6 HealthRequest ''
  frame 5 ListPlannersRequest ''
} > "$seeds/session"
frame 0 LoadWorldRequest 'sdf_text: "<sdf version=\"1.9\"><world name=\"w\"><model name=\"box\"><static>true</static><link name=\"l\"><collision name=\"c\"><geometry><box><size>1 1 1</size></box></geometry></collision></link></model></world></sdf>" sdf_resolution: 0.1' > "$seeds/sdf_text"
frame 0 LoadWorldRequest 'map_yaml_path: "worlds/office/office.yaml"' > "$seeds/path_without_root"
# Kept (found by probing the handlers): an inflation radius of 1e6 m inflated the whole map
# without end, and a time budget of 1e6 s planned for as long; both are refused now.
{
  frame 0 LoadWorldRequest "$small_map inflation_radius: 1000000"
} > "$root/fuzz/regressions/navd_requests/huge_inflation"
{
  frame 0 LoadWorldRequest "$small_map"
  frame 4 PlanPathRequest 'world_id: "world-1" start { x: 0.15 y: 0.15 } goal { x: 0.65 y: 0.65 } time_budget: 1000000'
} > "$root/fuzz/regressions/navd_requests/huge_time_budget"
echo "wrote the map_server and navd_requests seeds and kept inputs"
