-- golden.lua — the scenes of the golden-image tests (tests/lua/render_spec.lua,
-- "golden images"), written at full float precision for
-- scripts/compare_revisions.sh:
--
--   outcrop run scripts/compare/golden.lua --out DIR
--
-- The spec compares against tests/fixtures/render/*.exr with a tolerance;
-- here two builds are compared byte for byte.
local oc = require "outcrop"

local function ball(c, r) return oc.point{center = c, radius = r} end
local scene = ball({0, 0, 2}, 4) + oc.box{min = {-10, -10, -4}, max = {10, 10, -1}, falloff = 1}
local cam = {eye = {16, -20, 12}, target = {0, 0, 0}, fov = 40}
local cases = {
  {"sphere_plane", {size = {64, 48}, camera = cam, aov = false}},
  {"sphere_plane_function", {size = {64, 48}, camera = cam, aov = false,
    color = function(x, y, z, nx, ny, nz)
      local band = math.floor(z) % 2 == 0 and 0.8 or 0.4
      return band * (0.5 + 0.5 * nz * nz), 0.3, 0.6 - 0.2 * band
    end}},
  -- the same scenes with the AOVs (on by default)
  {"sphere_plane_aov", {size = {64, 48}, camera = cam}},
}
for _, c in ipairs(cases) do
  local img = oc.render(scene, c[2])
  assert(img:write(c[1] .. ".exr", {bits = 32}))
  print("golden: wrote " .. c[1] .. ".exr")
end
