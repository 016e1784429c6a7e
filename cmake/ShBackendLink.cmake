# The link feature sh_backend: $<LINK_LIBRARY:sh_backend,lib> keeps a
# backend's library in a program that names none of its symbols.  Backends
# register themselves as their library loads, so a program that uses them
# only by name (backend("cpu")) references nothing in them, and a linker
# that drops such libraries (GNU ld's --as-needed, the default of Debian's
# and Ubuntu's compilers) or such archive members would leave them out.
# SH_SHARED_LIBS says how the backends were built: shared libraries are
# kept with --no-as-needed, static ones whole (--whole-archive).
if(SH_SHARED_LIBS)
  set(CMAKE_LINK_LIBRARY_USING_sh_backend "LINKER:--push-state,--no-as-needed" "<LINK_ITEM>" "LINKER:--pop-state")
else()
  set(CMAKE_LINK_LIBRARY_USING_sh_backend "LINKER:--push-state,--whole-archive" "<LINK_ITEM>" "LINKER:--pop-state")
endif()
set(CMAKE_LINK_LIBRARY_USING_sh_backend_SUPPORTED TRUE)
