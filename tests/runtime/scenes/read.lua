-- read.lua PATH: prints the first line of PATH.
local f = assert(io.open(arg[1]))
print("read", f:read("l"))
f:close()
