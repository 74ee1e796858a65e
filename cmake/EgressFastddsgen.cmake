# Runs fastddsgen on one ROS 2 IDL file so that parallel build jobs cannot race:
#   cmake -DFASTDDSGEN=<exe> -DIDL_ROOT=<idl root> -DIDL=<a/msg/B.idl> -DOUT=<dir> -P EgressFastddsgen.cmake
# fastddsgen preprocesses into <temp dir>/<Name>.idl.cc (default /tmp, shared by every job and
# every build on the machine) and also regenerates every type the file includes into its output
# directory. Two jobs for files that include one another (JointTrajectory and JointTrajectoryPoint)
# then truncate and read the same files at once, and the parser fails ("project is null"). So each
# run gets its own staging directory as both temp and output directory, and only the file's own
# four outputs are copied to OUT (the generated headers include dependencies by their package
# path, `builtin_interfaces/msg/Duration.h`, so the copies of them are never needed).
get_filename_component(_name ${IDL} NAME_WE)
set(_stage ${OUT}/.fastddsgen-${_name})
file(REMOVE_RECURSE ${_stage})
file(MAKE_DIRECTORY ${_stage})
execute_process(
  COMMAND ${FASTDDSGEN} -typeros2 -cs -replace -t ${_stage} -I ${IDL_ROOT} -d ${_stage}
          ${IDL_ROOT}/${IDL}
  RESULT_VARIABLE _rc
  OUTPUT_VARIABLE _log
  ERROR_VARIABLE _log)
file(WRITE ${OUT}/${_name}.fastddsgen.log "${_log}")
set(_files ${_name}.h ${_name}.cxx ${_name}PubSubTypes.h ${_name}PubSubTypes.cxx)
foreach(_f ${_files})
  if(NOT _rc EQUAL 0 OR NOT EXISTS ${_stage}/${_f})
    message(FATAL_ERROR "fastddsgen failed on ${IDL_ROOT}/${IDL} (exit ${_rc}, no ${_f}):\n${_log}")
  endif()
endforeach()
foreach(_f ${_files})
  file(COPY_FILE ${_stage}/${_f} ${OUT}/${_f})
endforeach()
file(REMOVE_RECURSE ${_stage})
