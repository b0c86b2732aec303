-- coroutine.lua: coroutine.resume and coroutine.wrap (wrapped by the
-- interpreter for Ctrl-C) behave as in stock Lua.
local gen = coroutine.wrap(function(a)
  local b = coroutine.yield(a + 1)
  coroutine.yield(b * 2)
  return "done"
end)
assert(gen(1) == 2 and gen(5) == 10 and gen() == "done")

local co = coroutine.create(function(...) return select("#", ...), coroutine.yield(...) end)
local ok, x, y = coroutine.resume(co, "x", "y")
assert(ok and x == "x" and y == "y")
local ok2, n, z = coroutine.resume(co, "z")
assert(ok2 and n == 2 and z == "z" and coroutine.status(co) == "dead")
local ok3, msg3 = coroutine.resume(co)
assert(not ok3 and msg3:find("dead coroutine"))

-- an error inside a wrap function gets the caller's position prepended
local bad = coroutine.wrap(function() error("inner") end)
local ok4, msg4 = pcall(function() bad() end)
assert(not ok4 and msg4:find("^.*coroutine%.lua:20: .*coroutine%.lua:19: inner$"), msg4)
assert(not pcall(coroutine.wrap, 42))
print("coroutines ok")
