-- terrain_spec.lua — outcrop.terrain: the implicit surface embeds the
-- heightfield (bisection on random columns against hf:height), inversion
-- and floating islands, masks, the gradient, the options and their
-- errors (with the script line), a DEM meshed closed, and lifetimes.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "terrain_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end

local hf = oc.heightfield.fbm{size = {65, 49}, cell = 2, amplitude = 12,
                              wavelength = 40, seed = 4}
local X1, Y1 = 128, 96 -- the grid spans [0, 128] x [0, 96]

-- z in [lo, hi] where node crosses T (f > T at lo, f < T at hi, or the
-- reverse)
local function crossing(node, x, y, lo, hi)
  local T = oc.threshold
  local lo_in = node:eval(x, y, lo) > T
  assert.are_not.equal(lo_in, node:eval(x, y, hi) > T)
  for _ = 1, 70 do
    local m = 0.5 * (lo + hi)
    if (node:eval(x, y, m) > T) == lo_in then lo = m else hi = m end
  end
  return 0.5 * (lo + hi)
end

describe("outcrop.terrain", function()
  it("embeds the heightfield on random columns", function()
    local t = oc.terrain(hf, {falloff = 6})
    assert.are.equal("terrain", t:kind())
    local x0, y0, z0, x1, y1, z1 = t:bounds()
    assert.are.same({0, 0, X1, Y1}, {x0, y0, x1, y1})
    math.randomseed(3)
    for _ = 1, 200 do
      local x, y = 6 + math.random() * (X1 - 12), 6 + math.random() * (Y1 - 12)
      local h = hf:height(x, y)
      local z = crossing(t, x, y, z0 + 6 - 0.05, z1)
      assert.is_true(math.abs(z - h) < 1e-3 * 2)
      assert.is_true(t:eval(x, y, h - 0.2) > 0.5 and t:eval(x, y, h + 0.2) < 0.5)
    end
  end)

  it("has sigma's profile: T at the surface, 2T and 0 beyond the transition",
     function()
    local t = oc.terrain(hf, {falloff = 6, transition = 0.75})
    local h = hf:height(60, 40)
    assert.is_true(math.abs(t:eval(60, 40, h) - 0.5) < 1e-12)
    assert.are.equal(0, t:eval(60, 40, h + 0.76))
    assert.are.equal(1, t:eval(60, 40, h - 0.76))
    -- the paper's cubic: T + x + (3T - 2W)/W^2 x^2 + (W - 2T)/W^3 x^3
    local x, W, T = 0.3, 0.75, 0.5
    local s = T + x + (3 * T - 2 * W) / W ^ 2 * x ^ 2 + (W - 2 * T) / W ^ 3 * x ^ 3
    assert.is_true(math.abs(t:eval(60, 40, h - x) - s) < 1e-12)
  end)

  it("has an analytic gradient", function()
    local t = oc.terrain(hf, {falloff = 5})
    math.randomseed(8)
    for _ = 1, 100 do
      local p = {math.random() * X1, math.random() * Y1,
                 hf:height(40, 40) + (math.random() - 0.5) * 30}
      local gx, gy, gz = t:gradient(p[1], p[2], p[3])
      local n = R.numgrad(t, p, 1e-6)
      local e = math.sqrt((gx - n[1]) ^ 2 + (gy - n[2]) ^ 2 + (gz - n[3]) ^ 2)
      assert.is_true(e < 1e-5 * (1 + math.sqrt(n[1] ^ 2 + n[2] ^ 2 + n[3] ^ 2)))
    end
  end)

  it("inverts, and makes floating islands with an inverted terrain",
     function()
    local top = oc.terrain(hf, {falloff = 6})
    local under = oc.heightfield.fbm{size = {65, 49}, cell = 2, amplitude = 3,
                                     wavelength = 30, seed = 9}
    local lo = hf:min() - 12
    local bottom = oc.terrain(under, {falloff = 6, invert = true,
                                      thickness = 200})
    local inv = oc.terrain(hf, {falloff = 6, invert = true})
    local h = hf:height(50, 50)
    assert.is_true(inv:eval(50, 50, h + 0.2) > 0.5)
    assert.is_true(inv:eval(50, 50, h - 0.2) < 0.5)
    local island = top & oc.transform(bottom, {translate = {0, 0, lo}})
    local hb = under:height(50, 50) + lo
    assert.is_true(island:eval(50, 50, 0.5 * (h + hb)) > 0.5)
    assert.is_true(island:eval(50, 50, hb - 0.2) < 0.5)
    assert.is_true(island:eval(50, 50, h + 0.2) < 0.5)
  end)

  it("takes any horizontal domain from a mask", function()
    local m = oc.heightfield.from(function(x, y)
      return ((x - 64) ^ 2 + (y - 48) ^ 2 < 30 ^ 2) and 1 or 0
    end, {size = {65, 49}, cell = 2})
    local t = oc.terrain(hf, {falloff = 4, mask = m})
    local h = hf:height(64, 48)
    assert.is_true(t:eval(64, 48, h - 0.1) > 0.5)
    for _, p in ipairs{{5, 5}, {120, 90}, {64, 85}} do
      for z = -40, 40, 5 do assert.are.equal(0, t:eval(p[1], p[2], z)) end
    end
  end)

  it("meshes a DEM closed", function()
    local t = oc.terrain(hf, {falloff = 6})
    local _, _, z0, _, _, z1 = t:bounds()
    local mesh = oc.polygonize(t, {box = {-1, -1, z0 - 1, X1 + 1, Y1 + 1, z1 + 1},
                                   cell = 1.5})
    local v, tri = mesh:counts()
    -- closed triangle mesh of a slab: 3T = 2E, V - E + T = 2
    assert.are.equal(2, v - tri / 2)
  end)

  it("checks its arguments", function()
    check(function() oc.terrain(42) end, "outcrop.terrain",
          "expected a heightfield")
    check(function() oc.terrain(hf, {falloff = -1}) end, "outcrop.terrain",
          "'falloff'")
    check(function() oc.terrain(hf, {falloff = 0 / 0}) end, "outcrop.terrain",
          "'falloff'")
    check(function() oc.terrain(hf, {falloff = 1e9}) end, "outcrop.terrain",
          "'falloff'")
    check(function() oc.terrain(hf, {transition = 0}) end, "outcrop.terrain",
          "'transition'")
    check(function() oc.terrain(hf, {thickness = -2}) end, "outcrop.terrain",
          "'thickness'")
    check(function() oc.terrain(hf, {invert = 1}) end, "outcrop.terrain",
          "'invert'")
    check(function() oc.terrain(hf, {mask = 3}) end, "outcrop.terrain",
          "'mask'")
    check(function() oc.terrain(hf, {mask = "/nonexistent/mask.png"}) end,
          "outcrop.terrain", "'mask'", "mask.png")
    check(function() oc.terrain(hf, {fallof = 2}) end, "outcrop.terrain",
          "fallof")
    check(function() oc.terrain(hf, {}, 3) end, "outcrop.terrain")
  end)

  it("keeps its grid alive", function()
    local t = oc.terrain(oc.heightfield.fbm{size = {33, 33}, cell = 1,
                                            amplitude = 2, wavelength = 9})
    collectgarbage()
    collectgarbage()
    assert.is_true(t:eval(16, 16, -50) >= 0)
    assert.is_true(t:lipschitz() > 0)
  end)
end)
