-- sandbox.lua: what the sandbox removes or restricts (no --unsafe).
assert(os.execute == nil, "os.execute")
assert(os.setlocale == nil, "os.setlocale")
assert(io.popen == nil, "io.popen")
assert(package.loadlib == nil, "package.loadlib")
assert(#package.searchers == 2, "only the preload and Lua searchers")
assert(package.loaded.io.open == io.open, "package.loaded sees the same io")
assert(debug.sethook == nil and debug.getregistry == nil
       and debug.getupvalue == nil, "debug library reduced")
assert(type(debug.traceback) == "function", "debug.traceback kept")
assert(not pcall(os.tmpname), "os.tmpname refused")
-- io.tmpfile writes in /tmp, outside --out and without limit
local tok, tmsg = pcall(io.tmpfile)
assert(not tok and tmsg:find("io.tmpfile is not allowed", 1, true), tmsg)

-- binary chunks are refused by load, loadfile and require
local bytecode = string.dump(function() return 42 end)
local f, msg = load(bytecode)
assert(f == nil and msg:find("binary"), "load of bytecode")
assert(load(bytecode, "x", "b") == nil, "load with mode 'b'")
assert(load("return 6 * 7")() == 42, "load of text still works")
-- run with the output folder as current folder, so the file written
-- below is also the one read back
local out = assert(io.open("bytecode.lua", "wb"))
out:write(bytecode)
out:close()
local g, lmsg = loadfile("bytecode.lua")
assert(g == nil and lmsg:find("binary"), "loadfile of bytecode")
assert(not pcall(dofile, "bytecode.lua"), "dofile of bytecode")
package.path = "./?.lua"
local ok, rmsg = pcall(require, "bytecode")
assert(not ok and rmsg:find("binary"), "require of bytecode")
print("sandbox ok")
