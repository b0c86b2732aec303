-- write.lua PATH [MODE]: writes "written\n" to PATH with io.open.
local f = assert(io.open(arg[1], arg[2] or "w"))
f:write("written\n")
f:close()
print("wrote", arg[1])
