# Finds what the Python module needs: an interpreter that has numpy and pybind11 (Debian's
# python3-numpy and python3-pybind11 live in /usr/bin/python3's dist-packages, which another
# `python3` earlier on PATH, such as a pyenv shim, may lack), its development files and
# pybind11's CMake package. Sets PRIMSEG_PYTHON_FOUND. Pass -DPython3_EXECUTABLE=... to choose.
set(PRIMSEG_PYTHON_FOUND OFF)
if(NOT Python3_EXECUTABLE)
  find_program(primseg_path_python3 python3)
  foreach(candidate ${primseg_path_python3} /usr/bin/python3)
    if(candidate AND EXISTS ${candidate})
      execute_process(COMMAND ${candidate} -c "import numpy, pybind11"
                      RESULT_VARIABLE import_status OUTPUT_QUIET ERROR_QUIET)
      if(import_status EQUAL 0)
        set(Python3_EXECUTABLE ${candidate} CACHE FILEPATH "Python interpreter of the module")
        break()
      endif()
    endif()
  endforeach()
endif()
if(Python3_EXECUTABLE)
  find_package(Python3 COMPONENTS Interpreter Development.Module NumPy QUIET)
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import pybind11; print(pybind11.get_cmake_dir())"
                  OUTPUT_VARIABLE primseg_pybind11_dir OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  find_package(pybind11 2.6 CONFIG QUIET HINTS ${primseg_pybind11_dir})
  if(Python3_FOUND AND Python3_NumPy_FOUND AND pybind11_FOUND)
    set(PRIMSEG_PYTHON_FOUND ON)
  endif()
endif()
