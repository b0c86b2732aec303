-- unsafe.lua: with --unsafe the standard library is whole.
assert(type(os.execute) == "function", "os.execute")
assert(type(io.popen) == "function", "io.popen")
assert(type(package.loadlib) == "function", "package.loadlib")
assert(type(debug.sethook) == "function", "debug.sethook")
local ok, how, code = os.execute("exit 3")
assert(ok == nil and how == "exit" and code == 3, "os.execute ran")
-- relative write paths are plain Lua: the current folder, not --out
local f = assert(io.open("unsafe.txt", "w"))
f:write("unsafe\n")
f:close()
print("unsafe ok")
