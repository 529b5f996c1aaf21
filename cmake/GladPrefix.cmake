# Gives every global symbol of a generated glad loader an sffd_ prefix (cmake -DHEADER=... -DGUARD=... -P):
# libsffd exports its symbols, and an application with a glad of its own (the usual GL loader) would
# otherwise interpose its table and loader on sffd's, or sffd's on its own. Source code keeps the glad
# names: the header maps them with #defines inserted after its include guard GUARD.
# With -DSOURCE=gles2.c -DSHARE_WITH=gl.c it also drops from SOURCE every definition SHARE_WITH has
# (the entry-point pointers and extension flags the two APIs share), so the ES loader fills the GL
# loader's table and the GL driver code calls one set of pointers on either kind of context.
file(READ ${HEADER} text)
string(REGEX MATCHALL "GLAD_API_CALL [A-Za-z0-9_]+ (glad_gl[A-Za-z0-9_]+|GLAD_GL_[A-Za-z0-9_]+|gladLoadGL[A-Za-z0-9]*)"
       decls "${text}")
set(defines "/* sffd: symbol prefix (cmake/GladPrefix.cmake) */\n")
foreach(d IN LISTS decls)
  string(REGEX REPLACE ".* " "" name "${d}")
  string(APPEND defines "#define ${name} sffd_${name}\n")
endforeach()
string(REPLACE "#define ${GUARD}\n" "#define ${GUARD}\n${defines}" text "${text}")
file(WRITE ${HEADER} "${text}")

if(DEFINED SOURCE)
  file(READ ${SHARE_WITH} shared)
  file(READ ${SOURCE} source)
  string(REGEX MATCHALL "\n(PFN[A-Z0-9_]+PROC glad_gl[A-Za-z0-9_]+ = NULL|int GLAD_GL_[A-Za-z0-9_]+ = 0);" defs "${shared}")
  foreach(def IN LISTS defs)
    string(REPLACE "${def}" "" source "${source}")
  endforeach()
  file(WRITE ${SOURCE} "${source}")
endif()
