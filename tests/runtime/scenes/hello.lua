-- hello.lua: prints what a scene sees of its command line.
print("module", type(outcrop), outcrop == require("outcrop"))
print("arg0", arg[0])
print("args", #arg, ...)
