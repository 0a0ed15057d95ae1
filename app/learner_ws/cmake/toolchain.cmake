# ROS 2 Classroom: what colcon's CMake needs to build against the ROS wheels.
# Given to every CMake package of a learner's workspace by our colcon extension
# (app/learner_ws/colcon_extension.py appends -DCMAKE_TOOLCHAIN_FILE=<this file>,
# -DPython3_EXECUTABLE and -DCLASSROOM_UNDERLAY to `colcon build`'s --cmake-args),
# in the Console and in a terminal alike, so the learner's CMakeLists.txt stays
# exactly as the tutorials write it.
#
# * The ROS packages live in the prefix of the Python that runs the build
#   (the project's virtual environment), CLASSROOM_UNDERLAY: AMENT_PREFIX_PATH
#   and CMAKE_PREFIX_PATH end with it.
# * Tests of ament_cmake packages need ament_lint_auto, which has no wheel:
#   BUILD_TESTING is off unless the command line turns it on.
# * After each project's CMakeLists.txt, drop include directories of the
#   wheels' build machine (/opt/python/...) from imported targets.
if(DEFINED CLASSROOM_UNDERLAY)
  # The wheels' prefix after whatever the workspace's own packages put first.
  if(DEFINED ENV{AMENT_PREFIX_PATH} AND NOT "$ENV{AMENT_PREFIX_PATH}" STREQUAL "")
    set(ENV{AMENT_PREFIX_PATH} "$ENV{AMENT_PREFIX_PATH}:${CLASSROOM_UNDERLAY}")
  else()
    set(ENV{AMENT_PREFIX_PATH} "${CLASSROOM_UNDERLAY}")
  endif()
  list(APPEND CMAKE_PREFIX_PATH "${CLASSROOM_UNDERLAY}")
endif()
set(BUILD_TESTING OFF CACHE BOOL "ament_lint_auto has no wheel")
set(CMAKE_PROJECT_INCLUDE "${CMAKE_CURRENT_LIST_DIR}/after_project.cmake" CACHE FILEPATH "")
