-- render_meta.lua NAME: renders a small scene and writes NAME (by its
-- extension), for the provenance and thread-count cases of run.sh.
local oc = outcrop
local scene = oc.point{center = {0, 0, 2}, radius = 4} +
  oc.box{min = {-10, -10, -4}, max = {10, 10, -1}, falloff = 1} +
  oc.segment{a = {-6, 4, 0}, b = {6, 5, 3}, radius = 2}
local img = oc.render(scene, {size = {96, 64}, aov = true,
  camera = {eye = {16, -20, 12}, target = {0, 0, 0}}})
local name = arg[1] or "render.png"
-- labels only (run.sh sets them to see them recorded)
local _ = oc.param("a"), oc.param("b")
assert(img:write(name, {bits = name:match("%.exr$") and 32 or nil}))
print("wrote", name)
