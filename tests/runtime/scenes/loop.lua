-- loop.lua [HOW]: signals that it started, then loops for ever, swallowing
-- errors, in the main thread or in coroutines (HOW: wrap, resume, nested),
-- or meshes for a long time in C (HOW: mesh); Ctrl-C must still stop it
-- before after.txt (or the mesh) is written.
local function spin()
  while true do
    pcall(function() while true do end end)
  end
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
elseif how == "nested" then
  coroutine.wrap(function()
    while true do pcall(coroutine.wrap(spin)) end
  end)()
else
  spin()
end
f = assert(io.open("after.txt", "w"))
f:close()
