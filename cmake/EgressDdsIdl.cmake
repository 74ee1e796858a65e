# Writes the DDS form of ROS 2 message IDL, as ROS 2's rosidl_generator_dds_idl does: each
# `pkg::msg::Name` becomes `pkg::msg::dds_::Name_` (the name ROS 2 types carry on the wire), so
# that an IDL compiler without fastddsgen's -typeros2 (Cyclone's idlc) names them the same.
#   cmake -DIN=<idl root> -DOUT=<output root> -DFILES="a/msg/B.idl;..." -P EgressDdsIdl.cmake
foreach(_rel ${FILES})
  file(READ ${IN}/${_rel} _text)
  # References to message types, then the struct's own name, then the extra module.
  string(REGEX REPLACE "([A-Za-z0-9_]+)::msg::([A-Za-z0-9_]+)" "\\1::msg::dds_::\\2_" _text
         "${_text}")
  string(REGEX REPLACE "struct ([A-Za-z0-9_]+) {" "struct \\1_ {" _text "${_text}")
  string(REPLACE "  module msg {" "  module msg { module dds_ {" _text "${_text}")
  string(REGEX REPLACE "\n  };\n};" "\n  }; };\n};" _text "${_text}")
  get_filename_component(_dir ${OUT}/${_rel} DIRECTORY)
  file(MAKE_DIRECTORY ${_dir})
  file(WRITE ${OUT}/${_rel} "${_text}")
endforeach()
