-- loop.lua [HOW]: signals that it started, then loops for ever, swallowing
-- errors, in the main thread or in coroutines (HOW: wrap, resume, nested),
-- in a __close handler run by coroutine.close (close) or by the end of a
-- coroutine.wrap function (wrap-close), in an xpcall
-- message handler called for an error raised by the stop itself (xpcall),
-- with a finalizer pending that would write after.txt (finalizer), or
-- loops in the standard library's C code (c), prints for ever (print), or
-- meshes for a long time in C (HOW: mesh); Ctrl-C must still stop it
-- before after.txt (or the mesh) is written.
local function spin()
  while true do
    pcall(function() while true do end end)
  end
end

-- an object kept until the end whose finalizer would write after.txt
local function pend_finalizer()
  pending = setmetatable({}, {__gc = function()
    local out = io.open("after.txt", "w")
    out:write("finalizer ran after the stop\n")
    out:close()
  end})
end

local f = assert(io.open("started.txt", "w"))
f:close()
local how = arg[1]
if how == "wrap" then
  coroutine.wrap(spin)()
elseif how == "resume" then
  while true do coroutine.resume(coroutine.create(spin)) end
elseif how == "mesh" then
  local p = outcrop.point{center = {0, 0, 0}, radius = 1}
  for _ = 1, 1000 do
    local m = outcrop.polygonize(p, {box = {-2, -2, -2, 2, 2, 2},
                                     resolution = {1000, 1000, 1000},
                                     full_grid = true})
    m:write("mesh.ply")
  end
elseif how == "close" then
  local co = coroutine.create(function()
    local _ <close> = setmetatable({}, {__close = spin})
    coroutine.yield()
  end)
  coroutine.resume(co)
  coroutine.close(co)
elseif how == "wrap-close" then
  -- the stop kills the coroutine from a hook: Lua would then close its
  -- variables with hooks off
  coroutine.wrap(function()
    local _ <close> = setmetatable({}, {__close = spin})
    spin()
  end)()
elseif how == "print" then
  -- prints for ever, swallowing errors, with a finalizer pending
  pend_finalizer()
  while true do pcall(print, "line") end
elseif how == "c" then
  -- a C loop over 2^63 absent slots: no hook can run in it
  table.move({}, 1, math.maxinteger, 1, {})
elseif how == "xpcall" then
  -- the stop raises its error from a hook, where Lua runs the handler
  -- with hooks off
  local function handler() while true do end end
  while true do xpcall(function() while true do end end, handler) end
elseif how == "finalizer" then
  pend_finalizer()
  spin()
elseif how == "nested" then
  coroutine.wrap(function()
    while true do pcall(coroutine.wrap(spin)) end
  end)()
else
  spin()
end
f = assert(io.open("after.txt", "w"))
f:close()
