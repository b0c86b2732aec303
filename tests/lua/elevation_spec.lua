-- elevation_spec.lua — outcrop.elevation (Génevaux et al. 2015): the
-- constructors against their formulas, gradients against central
-- differences, Lipschitz bounds never exceeded, statistics of a DAG, the
-- same tree from the same seed, and every error with its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "elevation_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local E = oc.elevation

local function wyvill(x)
  if x >= 1 then return 0 end
  local k = 1 - x * x
  return k * k * k
end

local rng_state = 777
local function rand(lo, hi)
  rng_state = (rng_state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * rng_state / 2147483648
end

local function scene()
  local base = E.disc{center = {0, 0}, radius = 2000, height = 100,
                      noise = {amplitude = 40, wavelength = 400, seed = 3}}
  local hill = E.disc{center = {300, 0}, radius = 600, height = 400,
                      noise = {kind = "ridged", amplitude = 120,
                               wavelength = 200, seed = 4}}
  return base, hill, E.blend{base, hill}
end

describe("outcrop.elevation.disc", function()
  it("has Wyvill's weight and a flat elevation without noise", function()
    local d = E.disc{center = {10, -5}, radius = 4, height = 7}
    for _ = 1, 50 do
      local x, y = rand(4, 16), rand(-11, 1)
      local f, a = d:eval(x, y)
      assert.are.equal(7, f)
      assert.is_true(math.abs(a - wyvill(math.sqrt((x - 10) ^ 2 +
                                                   (y + 5) ^ 2) / 4)) < 1e-14)
    end
    local x0, y0, lo, x1, y1, hi = d:bounds()
    assert.are.same({6, -9, 7, 14, -1, 7}, {x0, y0, lo, x1, y1, hi})
    assert.are.equal("disc", d:kind())
  end)

  it("ranges: plain noise around the height, ridged above it", function()
    local p = E.disc{center = {0, 0}, radius = 100, height = 20,
                     noise = {amplitude = 10, octaves = 3}}
    local r = E.disc{center = {0, 0}, radius = 100, height = 20,
                     noise = {kind = "ridged", amplitude = 10, octaves = 3}}
    local _, _, plo, _, _, phi = p:bounds()
    local _, _, rlo, _, _, rhi = r:bounds()
    assert.is_true(math.abs(plo - (20 - 17.5)) < 1e-9)
    assert.is_true(math.abs(phi - (20 + 17.5)) < 1e-9)
    assert.is_true(math.abs(rlo - 20) < 1e-9 and math.abs(rhi - 37.5) < 1e-9)
  end)
end)

describe("elevation operators", function()
  it("blend is the weighted mean where the weights reach 1/2", function()
    local base, hill, b = scene()
    for _ = 1, 100 do
      local x, y = rand(-1500, 1500), rand(-1500, 1500)
      local fa, aa = base:eval(x, y)
      local fb, ab = hill:eval(x, y)
      local f, a = b:eval(x, y)
      local S = aa + ab
      assert.is_true(math.abs(a - S) < 1e-12)
      local want = (aa * fa + ab * fb) / math.max(S, 0.5)
      assert.is_true(math.abs(f - want) < 1e-9 * (1 + math.abs(want)))
    end
  end)

  it("replace and add follow their formulas", function()
    local base, hill = scene()
    local lake = E.disc{center = {-500, 0}, radius = 300, height = 20}
    local r = E.replace(base, lake)
    local rl = E.replace(base, lake, {weight = "lerp"})
    local ad = E.add(base, hill, {below = 150, fade = 30})
    for _ = 1, 100 do
      local x, y = rand(-900, 900), rand(-600, 600)
      local fa, aa = base:eval(x, y)
      local fb, ab = lake:eval(x, y)
      local w = math.min(math.max(ab, 0), 1)
      local f, a = r:eval(x, y)
      assert.is_true(math.abs(f - ((1 - w) * fa + w * fb)) < 1e-9)
      assert.are.equal(aa, a)
      local _, al = rl:eval(x, y)
      assert.is_true(math.abs(al - ((1 - w) * aa + w * w)) < 1e-12)
      local fh, ah = hill:eval(x, y)
      local c = math.min(math.max(ah, 0), 1)
      local t = math.min(math.max((150 - fa) / 30, 0), 1)
      local W = t * t * (3 - 2 * t)
      local fadd = ad:eval(x, y)
      assert.is_true(math.abs(fadd - (fa + c * W * fh)) < 1e-9)
    end
  end)

  it("add's slope weight follows its formula, with exact gradients",
     function()
    local base, hill = scene()
    local step = 4
    local ad = E.add(base, hill, {slope = 12, slope_fade = 8, slope_step = step})
    local n = {one = 0, zero = 0, mid = 0}
    for _ = 1, 150 do
      local x, y = rand(-900, 900), rand(-600, 600)
      local fa = base:eval(x, y)
      local fh, ah = hill:eval(x, y)
      local c = math.min(math.max(ah, 0), 1)
      local dx = (base:eval(x + step, y) - base:eval(x - step, y)) / (2 * step)
      local dy = (base:eval(x, y + step) - base:eval(x, y - step)) / (2 * step)
      local deg = math.deg(math.atan(math.sqrt(dx * dx + dy * dy)))
      local t = math.min(math.max((deg - 12) / 8, 0), 1)
      local S = 1 - t * t * (3 - 2 * t)
      if S == 1 then n.one = n.one + 1 elseif S == 0 then n.zero = n.zero + 1
      else n.mid = n.mid + 1 end
      local f = ad:eval(x, y)
      assert.is_true(math.abs(f - (fa + c * S * fh)) < 1e-9 * (1 + math.abs(f)))
      local h = 1e-4
      local gx, gy = ad:gradient(x, y)
      local nx = (ad:eval(x + h, y) - ad:eval(x - h, y)) / (2 * h)
      local ny = (ad:eval(x, y + h) - ad:eval(x, y - h)) / (2 * h)
      assert.is_true(math.abs(gx - nx) < 1e-3 * (1 + math.abs(nx)))
      assert.is_true(math.abs(gy - ny) < 1e-3 * (1 + math.abs(ny)))
      assert.is_true(math.sqrt(gx * gx + gy * gy) <= ad:lipschitz())
    end
    assert.is_true(n.one > 5 and n.zero > 5 and n.mid > 5)
  end)

  it("transform maps points and elevations, and concatenates", function()
    local _, hill = scene()
    local t = E.transform(hill, {translate = {1000, 0}, rotate = 90,
                                 scale = 2, vscale = 0.5, voffset = 10})
    -- p = 2 R90 p' + (1000, 0): p' = (300, 0) is at (1000, 600)
    local f, a = t:eval(1000, 600)
    local fh, ah = hill:eval(300, 0)
    assert.is_true(math.abs(f - (0.5 * fh + 10)) < 1e-9)
    assert.is_true(math.abs(a - ah) < 1e-12)
    local tt = E.transform(t, {translate = {5, 5}})
    assert.are.equal(2, tt:stats().nodes)
  end)

  it("gradients match central differences", function()
    local _, _, b = scene()
    local w = E.warp(b, {amplitude = 20, wavelength = 800})
    for _, e in ipairs{b, w} do
      for _ = 1, 40 do
        local x, y, h = rand(-1500, 1500), rand(-1500, 1500), 1e-4
        local gx, gy = e:gradient(x, y)
        local nx = (e:eval(x + h, y) - e:eval(x - h, y)) / (2 * h)
        local ny = (e:eval(x, y + h) - e:eval(x, y - h)) / (2 * h)
        assert.is_true(math.abs(gx - nx) < 1e-3 * (1 + math.abs(nx)))
        assert.is_true(math.abs(gy - ny) < 1e-3 * (1 + math.abs(ny)))
      end
    end
  end)

  it("never exceeds its Lipschitz bound", function()
    local _, _, b = scene()
    local L = b:lipschitz()
    for _ = 1, 2000 do
      local x, y = rand(-2500, 2500), rand(-2500, 2500)
      local gx, gy = b:gradient(x, y)
      assert.is_true(math.sqrt(gx * gx + gy * gy) <= L)
    end
  end)

  it("counts a DAG's nodes once, and the same seed gives the same tree",
     function()
    local base, hill, b = scene()
    local moved = E.transform(hill, {translate = {500, 500}})
    local s = E.blend{b, moved, hill}:stats()
    assert.are.same({nodes = 5, primitives = 2}, {nodes = s.nodes,
                                                  primitives = s.primitives})
    assert.is_true(s.bytes > 0 and s.bytes <= 300 * 5)
    local _, _, b2 = scene()
    assert.are.equal(b:eval(123, 456), b2:eval(123, 456))
    assert.are.equal(base:eval(1, 2), (scene()):eval(1, 2))
  end)
end)

describe("elevation errors", function()
  it("name the function, the field and the line", function()
    local _, _, b = scene()
    check(function() E.disc{center = {0, 0}, radius = -1} end,
          "outcrop.elevation.disc", "'radius'")
    check(function() E.disc{center = {0, 0}} end,
          "outcrop.elevation.disc", "'radius'")
    check(function() E.disc{center = {0, 0, 0}, radius = 1} end,
          "outcrop.elevation.disc", "'center'")
    check(function() E.disc{center = {0, 0}, radius = 1, hieght = 2} end,
          "outcrop.elevation.disc", "hieght")
    local c0, nan = {0, 0}, 0 / 0
    check(function() E.disc{center = c0, radius = 1, noise = {kind = "fbm"}} end,
          "outcrop.elevation.disc", "'noise.kind'")
    check(function() E.disc{center = c0, radius = 1, noise = {amplitude = nan}} end,
          "outcrop.elevation.disc", "'noise.amplitude'")
    check(function() E.disc{center = {0, 0}, radius = 1e308, height = 1e308,
                            noise = {amplitude = 1e308}} end,
          "outcrop.elevation.disc", "overflow")
    check(function() E.blend{} end, "outcrop.elevation.blend", "at least one")
    check(function() E.blend{b, 3} end, "outcrop.elevation.blend", "element 2")
    check(function() E.replace(b, {}) end, "outcrop.elevation.replace",
          "argument #2")
    check(function() E.replace(b, b, {weight = "b"}) end,
          "outcrop.elevation.replace", "'weight'")
    check(function() E.add(b, b, {fade = 0}) end, "outcrop.elevation.add",
          "'fade'")
    check(function() E.add(b, b, {slope = 0 / 0}) end, "outcrop.elevation.add",
          "'slope'")
    check(function() E.add(b, b, {slope = -3}) end, "outcrop.elevation.add",
          "'slope'", "[0, 90)")
    check(function() E.add(b, b, {slope = 90}) end, "outcrop.elevation.add",
          "'slope'", "[0, 90)")
    check(function() E.add(b, b, {slope = 30, slope_fade = 0}) end,
          "outcrop.elevation.add", "'slope_fade'")
    check(function() E.add(b, b, {slope = 30, slope_step = -1}) end,
          "outcrop.elevation.add", "'slope_step'")
    check(function() E.add(b, b, {slope = "steep"}) end,
          "outcrop.elevation.add", "'slope'")
    check(function() E.warp(b, {amplitude = 500, wavelength = 10}) end,
          "outcrop.elevation.warp", "bijection")
    check(function() E.transform(b, {scale = 0}) end,
          "outcrop.elevation.transform", "'scale'")
    check(function() E.transform(b, {vscale = 0}) end,
          "outcrop.elevation.transform", "'vscale'")
    check(function() b:eval(1) end, "elevation:eval", "argument #2")
    check(function() b.eval(3, 1, 2) end, "elevation:eval", "self")
    local f, a = b:eval(0 / 0, 0)
    assert.is_true(f ~= f and a ~= a)
  end)
end)
