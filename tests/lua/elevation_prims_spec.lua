-- elevation_prims_spec.lua — outcrop.elevation.lake and .image (Génevaux
-- et al. 2015, sections 4 and 4.2): values against the formulas, the
-- shore through the contour's vertices, alpha 1 inside and 0 beyond the
-- falloff, gradients against central differences, Lipschitz bounds never
-- exceeded, the grids kept alive by the node (closed or collected), and
-- every error naming its field and the script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "elevation_prims_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local E = oc.elevation

local function wyvill(x)
  if x <= 0 then return 1 end
  if x >= 1 then return 0 end
  local k = 1 - x * x
  return k * k * k
end

local rng_state = 4242
local function rand(lo, hi)
  rng_state = (rng_state * 1103515245 + 12345) % 2147483648
  return lo + (hi - lo) * rng_state / 2147483648
end

local function check_gradient(e, x, y, tol)
  local h = 1e-5
  local gx, gy = e:gradient(x, y)
  local fx = (e:eval(x + h, y) - e:eval(x - h, y)) / (2 * h)
  local fy = (e:eval(x, y + h) - e:eval(x, y - h)) / (2 * h)
  local sc = 1 + math.abs(fx) + math.abs(fy)
  assert(math.abs(gx - fx) <= tol * sc and math.abs(gy - fy) <= tol * sc,
         string.format("gradient (%g, %g) vs (%g, %g) at (%g, %g)", gx, gy,
                       fx, fy, x, y))
end

-- The plane's Lipschitz bound on random pairs near (cx, cy); returns the
-- steepest ratio seen over the bound.
local function check_lipschitz(e, cx, cy, r)
  local L, worst = e:lipschitz(), 0
  local _, _, lo, _, _, hi = e:bounds()
  for _ = 1, 3000 do
    local px, py = cx + rand(-r, r), cy + rand(-r, r)
    local qx, qy = px + rand(-r / 20, r / 20), py + rand(-r / 20, r / 20)
    local fp, fq = e:eval(px, py), e:eval(qx, qy)
    local d = math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2)
    assert(math.abs(fp - fq) <= L * d * (1 + 1e-9) + 1e-12)
    assert(fp >= lo - 1e-9 and fp <= hi + 1e-9)
    local gx, gy = e:gradient(px, py)
    worst = math.max(worst, math.sqrt(gx * gx + gy * gy) / L)
  end
  assert(worst <= 1 + 1e-9)
  return worst
end

-- `local x <close>` is the script's only way to close an object early.
local function close(x)
  local c <close> = x
end

local function grid(fn)
  return oc.heightfield.from(fn, {size = {33, 25}, cell = 2, origin = {0, 0}})
end
local function hill(x, y)
  return 20 * math.exp(-((x - 30) ^ 2 + (y - 20) ^ 2) / 300) + 0.05 * x
end

describe("outcrop.elevation.lake", function()
  it("has the default bed: 5 deep, a flat shore, a 2 m bank", function()
    local l = E.lake{center = {10, 20}, radius = 100, level = 50}
    assert.are.equal("lake", l:kind())
    for _, k in ipairs{{0, 45}, {40, 45}, {50, 45}, {100, 50}, {112.5, 50},
                       {150, 52}, {300, 52}} do
      local a = rand(-math.pi, math.pi)
      local f = l:eval(10 + k[1] * math.cos(a), 20 + k[1] * math.sin(a))
      assert(math.abs(f - k[2]) < 1e-9, string.format("f(%g) = %.12g", k[1], f))
    end
    for _ = 1, 500 do
      local rho, a = rand(0, 170), rand(-math.pi, math.pi)
      local _, w = l:eval(10 + rho * math.cos(a), 20 + rho * math.sin(a))
      assert(math.abs(w - wyvill((rho - 100) / 50)) < 1e-12)
      if rho <= 100 then assert.are.equal(1, w) end
      if rho >= 150 then assert.are.equal(0, w) end
    end
    local x0, y0, lo, x1, y1, hi = l:bounds()
    assert(math.abs(x0 + 140) < 1e-9 and math.abs(y1 - 170) < 1e-9)
    assert(lo <= 45 and lo > 44.9 and hi >= 52 and hi < 52.1)
    assert(check_lipschitz(l, 10, 20, 160) > 0.9)
    for _ = 1, 100 do
      local rho, a = rand(2, 160), rand(-math.pi, math.pi)
      check_gradient(l, 10 + rho * math.cos(a), 20 + rho * math.sin(a), 1e-5)
    end
  end)

  it("runs its shore through a contour's vertices, with sector profiles",
     function()
    local pts, rr = {}, {70, 120, 90, 130, 60, 100}
    for k = 1, 6 do
      local a = (k - 1) * math.pi / 3 + 0.2
      pts[k] = {rr[k] * math.cos(a), rr[k] * math.sin(a)}
    end
    local l = E.lake{center = {0, 0}, contour = pts, level = 0, falloff = 30,
                     profiles = {
                       {angle = 0, knots = {{-25, -6}, {0, 0}, {20, 4}}},
                       {angle = 180, knots = {{-25, -6}, {-5, -1}, {0, 0},
                                              {30, 1}}}}}
    for k = 1, 6 do
      local f, w = l:eval(pts[k][1], pts[k][2])
      assert(math.abs(f) < 1e-9 and math.abs(w - 1) < 1e-12)
      local s = 1 + 15 / rr[k]
      local _, w2 = l:eval(pts[k][1] * s, pts[k][2] * s)
      assert(math.abs(w2 - wyvill(0.5)) < 1e-9)
    end
    assert.are.equal(-6, (l:eval(0, 0)))
    check_lipschitz(l, 0, 0, 170)
    for _ = 1, 200 do
      local rho, a = rand(3, 170), rand(-math.pi, math.pi)
      check_gradient(l, rho * math.cos(a), rho * math.sin(a), 1e-5)
    end
    -- a radii list: radius k at (k - 1) 90 degrees
    local q = E.lake{center = {0, 0}, radius = {50, 80, 60, 70}, depth = 2}
    assert(math.abs(q:eval(0, 80) - 0) < 1e-9)
    assert(math.abs(q:eval(0, 0) + 2) < 1e-12)
  end)

  it("carves a hill by replacement", function()
    local base = E.disc{center = {0, 0}, radius = 1000, height = 30,
                        noise = {amplitude = 10, wavelength = 150, seed = 2}}
    local t = E.replace(base, E.lake{center = {0, 0}, radius = 120, level = 25})
    assert(math.abs(t:eval(0, 0) - 20) < 1e-9)
    check_lipschitz(t, 0, 0, 250)
    local st = t:stats()
    assert.are.equal(3, st.nodes)
    assert.are.equal(2, st.primitives)
  end)

  it("refuses bad fields, naming them", function()
    local fn = "outcrop.elevation.lake"
    check(function() E.lake{center = {0, 0}} end, fn, "'radius'", "'contour'")
    check(function() E.lake{center = {0, 0}, radius = -3} end, fn, "'radius'")
    check(function() E.lake{center = {0, 0}, radius = 0 / 0} end, fn,
          "'radius'")
    check(function() E.lake{center = {0, 0}, radius = {1, 2}} end, fn,
          "'radius'")
    check(function() E.lake{center = {0, 0}, radius = {1, 2, "x"}} end, fn,
          "'radius[3]'")
    check(function() E.lake{center = {0, 0}, radius = 5, level = math.huge}
          end, fn, "'level'")
    check(function() E.lake{center = {0, 0}, radius = 5, falloff = 0} end, fn,
          "'falloff'")
    check(function() E.lake{center = {0, 0}, radius = 5, bank = -1} end, fn,
          "'bank'")
    local zig = {{1, 0}, {0, 1}, {1, 0.1}, {-1, 0}}
    check(function() E.lake{center = {0, 0}, contour = zig} end, fn,
          "'contour'", "star-shaped")
    check(function() E.lake{center = {0, 0}, contour = {{1, 0}, {0, 1}, {1}}}
          end, fn, "'contour[3]'")
    local steep = {{-80, -5}, {0, 0}}
    check(function() E.lake{center = {0, 0}, radius = 50, profile = steep} end,
          fn, "'profiles'", "flat")
    local far = {{angle = 400, knots = {{-5, -1}, {0, 0}}}}
    check(function() E.lake{center = {0, 0}, radius = 50, profiles = far} end,
          fn, "'profiles[1].angle'")
    check(function() E.lake{center = {0, 0}, radius = 5, radious = 2} end, fn,
          "radious")
  end)
end)

describe("outcrop.elevation.image", function()
  it("maps the grid on a quad by inverse bilinear mapping", function()
    local hf = grid(hill)
    local Q = {{100, 0}, {180, 20}, {170, 110}, {90, 80}}
    local e = E.image{heightfield = hf, quad = Q, height = 3, offset = 7,
                      falloff = 10}
    assert.are.equal("image", e:kind())
    -- the grid spans [0, 64] x [0, 48]
    for _ = 1, 500 do
      local u, v = rand(0, 1), rand(0, 1)
      local x = (1 - u) * (1 - v) * Q[1][1] + u * (1 - v) * Q[2][1] +
                u * v * Q[3][1] + (1 - u) * v * Q[4][1]
      local y = (1 - u) * (1 - v) * Q[1][2] + u * (1 - v) * Q[2][2] +
                u * v * Q[3][2] + (1 - u) * v * Q[4][2]
      local f = e:eval(x, y)
      local want = 7 + 3 * hf:height(64 * u, 48 * v)
      assert(math.abs(f - want) < 1e-8, string.format("%g vs %g", f, want))
    end
    -- corners: the grid's corners, and alpha 0 on the border
    local f, w = e:eval(100, 0)
    assert(math.abs(f - (7 + 3 * hf:get(1, 1))) < 1e-9 and w == 0)
    local _, wout = e:eval(300, 300)
    assert.are.equal(0, wout)
    local x0, y0, _, x1, y1 = e:bounds()
    assert.are.same({90, 0, 180, 110}, {x0, y0, x1, y1})
    assert(check_lipschitz(e, 135, 55, 80) > 0.5)
    for _ = 1, 200 do
      local u, v = rand(0.02, 0.98), rand(0.02, 0.98)
      local x = (1 - u) * (1 - v) * Q[1][1] + u * (1 - v) * Q[2][1] +
                u * v * Q[3][1] + (1 - u) * v * Q[4][1]
      local y = (1 - u) * (1 - v) * Q[1][2] + u * (1 - v) * Q[2][2] +
                u * v * Q[3][2] + (1 - u) * v * Q[4][2]
      check_gradient(e, x, y, 1e-4)
    end
  end)

  it("lays a grid along a segment with a clamped weight grid", function()
    local hf = grid(hill)
    local wg = grid(function(x, y) return 1.5 * math.sin(x / 8) end)
    local e = E.image{heightfield = hf, weight = wg,
                      segment = {{0, 0}, {0, 200}}, width = 60, falloff = 5}
    -- along +y: u = y / 200, v across from x = 30 (v = 0) to x = -30
    for _ = 1, 300 do
      local s, t = rand(0, 200), rand(-30, 30)
      local f, w = e:eval(t, s)
      local u, v = s / 200, (30 - t) / 60
      assert(math.abs(f - hf:height(64 * u, 48 * v)) < 1e-8)
      local ww = math.min(1, math.max(0, wg:height(64 * u, 48 * v)))
      local g = (1 - wyvill(s / 5)) * (1 - wyvill((200 - s) / 5)) *
                (1 - wyvill((30 - t) / 5)) * (1 - wyvill((t + 30) / 5))
      assert(math.abs(w - ww * g) < 1e-9)
    end
    check_lipschitz(e, 0, 100, 120)
  end)

  it("lays a grid along a curve: u by arc length, v across", function()
    local hf = grid(hill)
    -- a straight curve is the segment, beyond its ends and sides too
    local seg = E.image{heightfield = hf, segment = {{0, 0}, {0, 200}},
                        width = 60, falloff = 5, height = 2}
    local str = E.image{heightfield = hf, curve = {{0, 0}, {0, 90}, {0, 200}},
                        spline = "linear", width = 60, falloff = 5, height = 2}
    for _ = 1, 300 do
      local x, y = rand(-60, 60), rand(-40, 240)
      local f1, a1 = seg:eval(x, y)
      local f2, a2 = str:eval(x, y)
      assert(math.abs(f1 - f2) < 1e-8 and math.abs(a1 - a2) < 1e-9,
             string.format("(%g, %g): %g %g vs %g %g", x, y, f1, a1, f2, a2))
    end
    -- a winding one: exact gradients, its slope bound where alpha > 0
    local e = E.image{heightfield = hf, width = 20, height = 3, curve = {
      {0, 0}, {60, 40}, {120, -20}, {180, 30}}}
    local L, n = e:lipschitz(), 0
    for _ = 1, 2000 do
      local x, y = rand(-10, 190), rand(-40, 60)
      local f, a = e:eval(x, y)
      if a > 0 then
        n = n + 1
        local gx, gy = e:gradient(x, y)
        assert(math.sqrt(gx * gx + gy * gy) <= L)
        if a < 1 and n % 4 == 0 then check_gradient(e, x, y, 1e-4) end
      end
    end
    assert(n > 100)
  end)

  it("keeps its grids when Lua closes or collects them", function()
    local e, want
    do
      local hf <close> = grid(hill)
      local wg <close> = grid(function() return 0.8 end)
      e = E.image{heightfield = hf, weight = wg,
                  quad = {{0, 0}, {10, 0}, {10, 10}, {0, 10}}}
      want = {e:eval(5, 5)}
    end
    collectgarbage()
    collectgarbage()
    local f, w = e:eval(5, 5)
    assert.are.equal(want[1], f)
    assert.are.equal(want[2], w)
    assert(math.abs(w - 0.8) < 1e-6)
    -- a metamethod closing the grid in the middle of the constructor
    local hf = grid(hill)
    local opts = setmetatable({heightfield = hf}, {__index = function(_, k)
      if k == "quad" then
        close(hf)
        return {{0, 0}, {10, 0}, {10, 10}, {0, 10}}
      end
    end})
    -- pinned: the close waits for the call, the node has its grid
    local img = E.image(opts)
    assert(math.abs(img:eval(0, 0) - hill(0, 0)) < 1e-4)
    local sq = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}
    check(function() return E.image{heightfield = hf, quad = sq} end,
          "outcrop.elevation.image", "closed")
  end)

  it("refuses bad fields, naming them", function()
    local fn, hf = "outcrop.elevation.image", grid(hill)
    local sq = {{0, 0}, {10, 0}, {10, 10}, {0, 10}}
    check(function() E.image{quad = sq} end, fn, "'heightfield'")
    check(function() E.image{heightfield = 3, quad = sq} end, fn,
          "'heightfield'")
    check(function() E.image{heightfield = hf, weight = {}, quad = sq} end,
          fn, "'weight'")
    check(function() E.image{heightfield = hf} end, fn, "'quad'", "'segment'")
    local concave = {{0, 0}, {10, 0}, {3, 3}, {0, 10}}
    check(function() E.image{heightfield = hf, quad = concave} end, fn,
          "'quad' must be convex")
    local cw = {{0, 0}, {0, 10}, {10, 10}, {10, 0}}
    check(function() E.image{heightfield = hf, quad = cw} end, fn,
          "counter-clockwise")
    local flat = {{0, 0}, {5, 0}, {10, 0}, {0, 10}}
    check(function() E.image{heightfield = hf, quad = flat} end, fn,
          "'quad' is degenerate")
    local three = {{0, 0}, {1, 0}, {1, 1}}
    check(function() E.image{heightfield = hf, quad = three} end, fn, "'quad'")
    local nanq = {{0, 0}, {1, 0 / 0}, {1, 1}, {0, 1}}
    check(function() E.image{heightfield = hf, quad = nanq} end, fn,
          "'quad[2]'")
    check(function() E.image{heightfield = hf, segment = {{0, 0}, {1, 1}}} end,
          fn, "'width'")
    local dot = {{0, 0}, {0, 0}}
    check(function() E.image{heightfield = hf, segment = dot, width = 2} end,
          fn, "'segment'")
    check(function() E.image{heightfield = hf, quad = sq, width = 2} end, fn,
          "'width'")
    check(function() E.image{heightfield = hf, quad = sq, height = 0} end, fn,
          "'height'")
    check(function() E.image{heightfield = hf, quad = sq, falloff = -1} end,
          fn, "'falloff'")
    check(function() E.image{heightfield = hf, quad = sq, offset = 1 / 0} end,
          fn, "'offset'")
    local wind = {{0, 0}, {60, 40}, {120, -20}, {180, 30}}
    check(function() E.image{heightfield = hf, curve = wind} end, fn,
          "'width'")
    check(function() E.image{heightfield = hf, curve = wind, width = 90} end,
          fn, "'width'", "curvature")
    check(function() E.image{heightfield = hf, curve = {{0, 0}}, width = 9} end,
          fn, "'curve'")
    check(function() E.image{heightfield = hf, curve = {{0, 0}, {1 / 0, 1}},
                             width = 9} end, fn, "'curve[2]'")
    check(function() E.image{heightfield = hf, curve = wind, quad = sq,
                             width = 9} end, fn, "'curve'", "'quad'")
    check(function() E.image{heightfield = hf, curve = wind, width = 9,
                             spline = "nurbs"} end, fn, "'spline'")
    check(function() E.image{heightfield = hf, quad = sq,
                             spline = "linear"} end, fn, "'spline'")
    check(function() E.image{heightfield = hf, width = 9, spline = "linear",
      curve = {{0, 0}, {10, 0}, {10, 10}}} end, fn, "'curve'", "corner")
  end)
end)
