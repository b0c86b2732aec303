-- render_loop.lua [HOW]: signals that it started, then renders for ever
-- (HOW = function: with a Lua colour function, so Ctrl-C lands in Lua
-- code called from the renderer); Ctrl-C must stop it before render.png
-- or after.txt is written.
local oc = outcrop
local f = assert(io.open("started.txt", "w"))
f:close()
local scene = oc.point{center = {0, 0, 0}, radius = 4}
local size, color, camera = {4000, 3000}, nil, nil
if arg[1] == "function" then
  -- a quick geometry pass, then a slow colour function on a view the
  -- sphere fills (seconds of Lua)
  size, camera = {400, 300}, {eye = {0, -6, 0}, target = {0, 0, 0}}
  color = function(x, y, z)
    local s = 0
    for i = 1, 20000 do s = s + i end
    return 0.5, 0.5, 0.5
  end
end
for _ = 1, 1000 do
  local img = oc.render(scene, {size = size, color = color, camera = camera})
  img:write("render.png")
end
f = assert(io.open("after.txt", "w"))
f:close()
