# Checks that the C API shared library exports the avm_* functions and no avatarmap C++ symbol.
# Usage: cmake -DLIB=<path to libavatarmap_c.so> -DNM=<nm> -P check_exports.cmake
execute_process(COMMAND ${NM} -D --defined-only ${LIB} OUTPUT_VARIABLE symbols
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NM} failed on ${LIB}")
endif()
foreach(fn avm_version avm_solver_create avm_solver_push avm_solver_sample avm_solve_file
           avm_bone_name avm_last_create_error avm_landmark_reader_open avm_landmark_reader_header
           avm_landmark_reader_read avm_landmark_reader_last_error avm_landmark_reader_destroy
           avm_solve_frames avm_solve_file_to_clip avm_clip_read avm_clip_get_poses avm_clip_add_poses
           avm_retargeter_apply_poses avm_capture_file avm_solver_options_init
           avm_solver_options_init_sized avm_estimator_options_init avm_estimator_options_init_sized
           avm_convert_file avm_convert_options_init avm_convert_options_init_sized
           avm_motion_input_kind avm_retargeter_create_with_options avm_retargeter_options_init
           avm_retargeter_options_init_sized avm_retargeter_reset avm_blendshape_name
           avm_blendshape_from_name)
  if(NOT symbols MATCHES " ${fn}\n")
    message(FATAL_ERROR "${LIB} does not export ${fn}")
  endif()
endforeach()
# Mangled names of the core live in namespace avatarmap: "...9avatarmap...".
string(REGEX MATCHALL "[^\n]*9avatarmap[^\n]*" leaked "${symbols}")
if(leaked)
  string(REPLACE ";" "\n" leaked "${leaked}")
  message(FATAL_ERROR "${LIB} exports C++ symbols of the core:\n${leaked}")
endif()
