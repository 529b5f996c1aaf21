# Gives every global symbol of the generated glad loader an sffd_ prefix (cmake -DHEADER=... -P):
# libsffd exports its symbols, and an application with a glad of its own (the usual GL loader) would
# otherwise interpose its table and loader on sffd's, or sffd's on its own. Source code keeps the glad
# names: the header maps them with #defines inserted after its include guard.
file(READ ${HEADER} text)
string(REGEX MATCHALL "GLAD_API_CALL [A-Za-z0-9_]+ (glad_gl[A-Za-z0-9_]+|GLAD_GL_[A-Za-z0-9_]+|gladLoadGL[A-Za-z]*)"
       decls "${text}")
set(defines "/* sffd: symbol prefix (cmake/GladPrefix.cmake) */\n")
foreach(d IN LISTS decls)
  string(REGEX REPLACE ".* " "" name "${d}")
  string(APPEND defines "#define ${name} sffd_${name}\n")
endforeach()
string(REPLACE "#define GLAD_GL_H_\n" "#define GLAD_GL_H_\n${defines}" text "${text}")
file(WRITE ${HEADER} "${text}")
