# Finds every third-party dependency of egress from Debian packages. Each lookup that fails stops
# the configure step with the name of the apt package to install (deps/apt-packages.txt lists them
# all; `./egress.sh deps` installs them). Wrapper targets give the libraries without imported
# targets (Bullet, OMPL) one so that module CMakeLists only ever link targets.

include_guard(GLOBAL)

# egress_require(<find_package args...> APT <debian-package>)
macro(egress_require)
  cmake_parse_arguments(_er "" "APT" "" ${ARGN})
  find_package(${_er_UNPARSED_ARGUMENTS} QUIET)
  list(GET _er_UNPARSED_ARGUMENTS 0 _er_name)
  if(NOT ${_er_name}_FOUND)
    message(FATAL_ERROR
      "egress: dependency '${_er_name}' not found. Install the Debian package '${_er_APT}':\n"
      "    apt-get install ${_er_APT}\n"
      "or run `./egress.sh deps` as root to install every missing package.")
  endif()
endmacro()

# egress_require_file(<var> <header> APT <debian-package> [PATH_SUFFIXES ...])
function(egress_require_header var header)
  cmake_parse_arguments(_eh "" "APT" "PATH_SUFFIXES" ${ARGN})
  find_path(${var} ${header} PATH_SUFFIXES ${_eh_PATH_SUFFIXES})
  if(NOT ${var})
    message(FATAL_ERROR
      "egress: header '${header}' not found. Install the Debian package '${_eh_APT}':\n"
      "    apt-get install ${_eh_APT}\n"
      "or run `./egress.sh deps` as root to install every missing package.")
  endif()
endfunction()

function(egress_require_library var name)
  cmake_parse_arguments(_el "" "APT" "" ${ARGN})
  find_library(${var} ${name})
  if(NOT ${var})
    message(FATAL_ERROR
      "egress: library '${name}' not found. Install the Debian package '${_el_APT}':\n"
      "    apt-get install ${_el_APT}\n"
      "or run `./egress.sh deps` as root to install every missing package.")
  endif()
endfunction()

# --- hsr_interface
egress_require(Eigen3 3.3 NO_MODULE APT libeigen3-dev)
egress_require(urdfdom APT liburdfdom-dev)
# urdfdom's CMake config carries no version; its pkg-config file does.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(EGRESS_URDFDOM_PC QUIET urdfdom)
endif()
set(urdfdom_VERSION "${EGRESS_URDFDOM_PC_VERSION}")
if(NOT urdfdom_VERSION)
  set(urdfdom_VERSION "unknown")
endif()

# --- hsr_interface/ros2: the real robot over ROS 2's middleware (Fast DDS, ROS 2's default),
# types generated from ROS 2 message IDL by fastddsgen; Cyclone DDS only for the interop test
# (a second DDS implementation no one here wrote).
egress_require(fastcdr APT libfastcdr-dev)
egress_require(fastrtps APT libfastrtps-dev)
# rosbag2's storage (sqlite3 .db3) for recorded runs.
egress_require(SQLite3 APT libsqlite3-dev)
find_program(EGRESS_FASTDDSGEN fastddsgen)
if(NOT EGRESS_FASTDDSGEN)
  message(FATAL_ERROR "egress: fastddsgen not found. Install the Debian package 'fastddsgen':\n"
    "    apt-get install fastddsgen\nor run `./egress.sh deps` as root.")
endif()
if(EGRESS_BUILD_TESTS)
  egress_require(CycloneDDS APT "cyclonedds-dev cyclonedds-tools")
  find_program(EGRESS_IDLC idlc)
  if(NOT EGRESS_IDLC)
    message(FATAL_ERROR "egress: idlc (Cyclone DDS's IDL compiler) not found. Install the Debian "
      "package 'cyclonedds-tools':\n    apt-get install cyclonedds-tools\nor run "
      "`./egress.sh deps` as root.")
  endif()
endif()

# --- twin
# Bullet in double precision: the robot model and every other module compute in double, and the
# twin's determinism and contact accuracy at door hinges benefit from it. Debian ships the
# -float64 libraries; its CMake config drags in BulletInverseDynamics (another package), so the
# three libraries we use are found directly.
egress_require_header(EGRESS_BULLET_INCLUDE_DIR btBulletDynamicsCommon.h APT libbullet-dev
                      PATH_SUFFIXES bullet)
egress_require_library(EGRESS_BULLET_DYNAMICS BulletDynamics-float64 APT libbullet-dev)
egress_require_library(EGRESS_BULLET_COLLISION BulletCollision-float64 APT libbullet-dev)
egress_require_library(EGRESS_BULLET_LINEARMATH LinearMath-float64 APT libbullet-dev)
if(NOT TARGET egress_ext::bullet)
  add_library(egress_ext::bullet INTERFACE IMPORTED GLOBAL)
  target_include_directories(egress_ext::bullet SYSTEM INTERFACE ${EGRESS_BULLET_INCLUDE_DIR})
  target_compile_definitions(egress_ext::bullet INTERFACE BT_USE_DOUBLE_PRECISION)
  target_link_libraries(egress_ext::bullet INTERFACE ${EGRESS_BULLET_DYNAMICS}
                        ${EGRESS_BULLET_COLLISION} ${EGRESS_BULLET_LINEARMATH})
endif()
egress_require(sdformat12 APT libsdformat-dev)
egress_require(assimp APT libassimp-dev)
egress_require(yaml-cpp APT libyaml-cpp-dev)

# --- perception
egress_require(OpenCV APT libopencv-dev COMPONENTS core imgproc imgcodecs videoio dnn)
# imgcodecs and videoio are linked only into the image module (perception/src/image_io_module.cpp):
# they pull in ~200 shared libraries, whose loading took 0.3-0.5 s of every egress start.
set(EGRESS_OPENCV_LINKED_LIBS opencv_core opencv_imgproc opencv_dnn)
set(EGRESS_OPENCV_MODULE_LIBS opencv_core opencv_imgcodecs opencv_videoio)
egress_require(octomap APT liboctomap-dev)

# --- planning
egress_require(ompl APT libompl-dev)
foreach(_boost_lib serialization filesystem system)
  egress_require_library(EGRESS_BOOST_${_boost_lib} boost_${_boost_lib}
                         APT libboost-${_boost_lib}-dev)
endforeach()
if(NOT TARGET egress_ext::ompl)
  add_library(egress_ext::ompl INTERFACE IMPORTED GLOBAL)
  target_include_directories(egress_ext::ompl SYSTEM INTERFACE ${OMPL_INCLUDE_DIRS})
  target_link_libraries(egress_ext::ompl INTERFACE ${OMPL_LIBRARIES})
endif()
egress_require(fcl APT libfcl-dev)

# --- behavior (the BehaviorTree.CPP v4 XML engine)
egress_require(tinyxml2 APT libtinyxml2-dev)
# Groot2 live monitoring (egress_bt_groot2): ZeroMQ, through its C API and pkg-config file.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(EGRESS_ZMQ QUIET IMPORTED_TARGET libzmq)
endif()
if(NOT EGRESS_ZMQ_FOUND)
  message(FATAL_ERROR
    "egress: dependency 'libzmq' not found. Install the Debian package 'libzmq3-dev':\n"
    "    apt-get install libzmq3-dev\n"
    "or run `./egress.sh deps` as root to install every missing package.")
endif()

# --- apps
egress_require(CLI11 APT libcli11-dev)
egress_require(fmt APT libfmt-dev)
egress_require(spdlog APT libspdlog-dev)
egress_require(nlohmann_json 3.2.0 APT nlohmann-json3-dev)
egress_require(Protobuf APT "libprotobuf-dev protobuf-compiler")
egress_require(gRPC CONFIG APT "libgrpc++-dev protobuf-compiler-grpc")

# --- tests and benchmarks
if(EGRESS_BUILD_TESTS)
  egress_require(GTest APT "libgtest-dev libgmock-dev")
endif()
if(EGRESS_BUILD_BENCHMARKS)
  egress_require(benchmark APT libbenchmark-dev)
  # Only bench/ik_bench: the issue asks for a comparison with KDL's ChainIkSolverPos_LMA.
  egress_require(orocos_kdl APT liborocos-kdl-dev)
endif()
