-- elev_instances.lua — thirty instances of one mountain patch, as
-- Génevaux et al. 2015, figures 15 and 23: one patch tree (a blend of four
-- noisy discs, built once) placed 30 times by outcrop.elevation.transform
-- (translate, rotate, scale, vscale) and blended over a covering base.
-- The tree is a DAG: every transform points at the same patch, so the
-- scene holds the patch's nodes once (e:stats() counts each node once).
--
--   outcrop run examples/elev_instances.lua [--set size=640] [--out DIR]

local oc = require "outcrop"
local E = oc.elevation

local w = oc.param("size", 640)
local h = w * 9 // 16
local count = oc.param("instances", 30)

-- The patch, in its own frame around the origin (about 500 m across).
local patch = E.blend{
  E.disc{center = {0, 0}, radius = 260, height = 110,
         noise = {kind = "turbulence", amplitude = 60, wavelength = 160, octaves = 2,
                  gain = 0.4, seed = 31}},
  E.disc{center = {90, 40}, radius = 170, height = 230,
         noise = {amplitude = 45, wavelength = 110, octaves = 2, gain = 0.4, seed = 32}},
  E.disc{center = {-100, -40}, radius = 180, height = 190,
         noise = {amplitude = 40, wavelength = 120, octaves = 2, gain = 0.4, seed = 33}},
  E.disc{center = {10, -120}, radius = 140, height = 120,
         noise = {kind = "turbulence", amplitude = 30, wavelength = 90, octaves = 2,
                  gain = 0.4, seed = 34}},
}
local pst = patch:stats()

-- Placements from a small linear congruential generator (the same ones
-- on every run): a jittered 6 x 5 grid over 2.4 x 2 km.
local state = 12345
local function rnd()
  state = (1103515245 * state + 12345) % 2147483648
  return state / 2147483648
end
-- 2.4 x 2 km; the base disc's terrain reaches 0.4542 x 3400 = 1544 m,
-- past the corners of the area the instances cover (1562 m: the corners
-- themselves are only base).
local parts = {E.disc{center = {0, 0}, radius = 3400, height = 20,
                      noise = {amplitude = 10, wavelength = 500, octaves = 3, seed = 30}}}
for i = 0, count - 1 do
  local gx, gy = i % 6, i // 6
  parts[#parts + 1] = E.transform(patch, {
    translate = {-1000 + 400 * gx + 160 * (rnd() - 0.5), -800 + 400 * gy + 160 * (rnd() - 0.5)},
    rotate = 360 * rnd(), scale = 0.7 + 0.6 * rnd(), vscale = 0.6 + 0.8 * rnd()})
end
local scene = E.blend(parts)

local st = scene:stats()
print(("elev_instances: the patch: %d nodes, %d primitives, %d bytes"):format(
  pst.nodes, pst.primitives, pst.bytes))
print(("elev_instances: %d instances: %d nodes, %d primitives, %d bytes (%d nodes if each instance were a copy)")
      :format(count, st.nodes, st.primitives, st.bytes, count * (pst.nodes + 1) + 2))
print(("elev_instances: Lipschitz bound %.1f"):format(scene:lipschitz()))

local t = os.clock()
local img = oc.render(scene, {
  size = {w, h},
  camera = {eye = {-1500, -1900, 1100}, target = {0, 0, 40}, fov = 40},
  rules = {sea_level = -100, snow_line = 230},
})
assert(img:write("elev_instances.png"))
print(("elev_instances: wrote elev_instances.png (%.1f s of CPU)"):format(os.clock() - t))
