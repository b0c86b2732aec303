-- demo.lua — a small rock arch: a perturbed Bezier curve standing on a
-- ground slab, a few hundred blended rock points along it, carved by
-- negative primitives; written out as slices through the field.
--
--   outcrop run examples/demo.lua [--set rocks=N] [--seed N] [--out DIR]

local oc = require "outcrop"

local nrocks = oc.param("rocks", 240)
local rng_seed = oc.seed
math.randomseed(rng_seed)

-- The ground: a slab whose top is at z = 0 (surface slightly above, where
-- the falloff crosses T).
local ground = oc.box{min = {-80, -45, -30}, max = {80, 45, -3}, falloff = 6}

-- The arch's spine: a cubic Bezier from one foot to the other.
local spine = {{-32, 0, -6}, {-34, 0, 44}, {34, 0, 44}, {32, 0, -6}}
local function bezier(t)
  local u = 1 - t
  local b = {u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t}
  local p = {0, 0, 0}
  for i = 1, 4 do
    for k = 1, 3 do p[k] = p[k] + b[i] * spine[i][k] end
  end
  return p
end

local arch = oc.perturb(
  oc.curve{points = spine, bezier = true, radius = 11, energy = 1},
  {wavelength = 9, amplitude = 3, octaves = 3})

-- Rocks: points scattered around the spine thicken it unevenly.
local rocks = {}
for i = 1, nrocks do
  local p = bezier(math.random())
  rocks[#rocks + 1] = oc.point{
    center = {p[1] + (math.random() - 0.5) * 10,
              p[2] + (math.random() - 0.5) * 12,
              p[3] + (math.random() - 0.5) * 10},
    radius = 4 + 4 * math.random(), energy = 0.35}
end

-- Carvers: negative points hollow the feet and pit the ground.
local carvers = {}
for i = 1, 40 do
  local side = i % 2 == 0 and 1 or -1
  carvers[#carvers + 1] = oc.point{
    center = {side * (30 + math.random() * 8), (math.random() - 0.5) * 14,
              -2 + math.random() * 10},
    radius = 3 + 3 * math.random(), energy = -0.6}
end
for i = 1, 30 do
  carvers[#carvers + 1] = oc.sphere{
    center = {(math.random() - 0.5) * 150, (math.random() - 0.5) * 80, -3},
    radius = 2 + 4 * math.random(), falloff = 3, energy = -1}
end

local scene = ground + arch + oc.blend(rocks) + oc.blend(carvers)

local st = scene:stats()
print(string.format("demo: %d nodes, %d primitives, %d bytes compiled",
                    st.nodes, st.primitives, st.bytes))

local outputs = {
  {"arch_xz.png", {plane = "xz", at = 0, box = {-80, -30, 80, 60}, size = {800, 450}}},
  {"arch_xy.png", {plane = "xy", at = 5, box = {-80, -45, 80, 45}, size = {800, 450}}},
  {"arch_yz.png", {plane = "yz", at = 32, box = {-45, -30, 45, 60}, size = {450, 450}}},
}
for _, o in ipairs(outputs) do
  local img = oc.slice(scene, o[2])
  assert(img:write(o[1]))
  print("demo: wrote " .. o[1])
end

-- The arch as a mesh, for Blender, Godot, MeshLab or three.js: rock
-- coloured by height through a palette.
local mesh = oc.polygonize(scene, {box = {-80, -45, -30, 80, 45, 60},
                                   cell = oc.param("cell", 0.75)})
-- 1 at the bottom of the box, falling to 0 at its top
local height = oc.plane{origin = {0, 0, -30}, normal = {0, 0, 1}, falloff = 90}
local colors = {field = height, palette = {{0.0, {0.55, 0.45, 0.35}},
                                           {0.6, {0.70, 0.58, 0.42}},
                                           {1.0, {0.45, 0.40, 0.36}}}}
for _, name in ipairs{"arch.ply", "arch.glb"} do
  assert(mesh:write(name, {colors = colors}))
  print("demo: wrote " .. name)
end
local ms = mesh:stats()
print(string.format("demo: mesh of %d vertices, %d triangles in %.2f s",
                    ms.vertices, ms.triangles, ms.seconds))

-- The arch rendered straight from the field (no mesh): rock, grass, snow
-- and sand by altitude and slope, sun shadows and ambient occlusion. The
-- EXR keeps, beside the colour, the depth (Z), normals (N.x, N.y, N.z),
-- positions (P.x, P.y, P.z) and field evaluations per pixel (evals).
local view = {eye = {-70, -150, 55}, target = {0, 0, 12}, fov = 35}
local picture = oc.render(scene, {camera = view, size = {960, 540},
                                  rules = {sea_level = -6, snow_line = 40},
                                  aov = true})
assert(picture:write("arch_render.png"))
print("demo: wrote arch_render.png")
assert(picture:write("arch_render.exr"))
print("demo: wrote arch_render.exr (colour, Z, N, P and evals)")
