-- queries_spec.lua — gradient, bounds, lipschitz, stats and the threshold
-- that queries compile with.
local oc = require "outcrop"
local R = require "helpers.ref"

local v0 = {0, 0, 0}
local nodes = {
  point = oc.point{center = {0.2, -0.1, 0.3}, radius = 1.5, energy = 0.9},
  sphere = oc.sphere{center = v0, radius = 0.5, falloff = 1},
  box = oc.box{min = {-0.3, -0.2, -0.1}, max = {0.4, 0.3, 0.2}, falloff = 0.9},
  segment = oc.segment{a = {-1, 0, 0}, b = {1, 0.5, 0}, radius = 1},
  curve = oc.curve{points = {{-1, 0, 0}, {0, 0.3, 0}, {1, 0, 0.4}}, radius = 1},
  cone = oc.cone{base = {0, 0, -0.5}, apex = {0, 0, 0.8}, radius = 0.6, falloff = 0.9},
  plane = oc.plane{origin = v0, normal = {0.2, 0.1, 1}, falloff = 1.2},
  turbulence = oc.turbulence{wavelength = 1.3, amplitude = 0.7, seed = 3},
}
do
  local a, b = nodes.point, nodes.segment
  nodes.blend = a + b + nodes.sphere
  nodes.smooth_union = oc.smooth_union{a, b, radius = 0.5}
  nodes.smooth_intersection = oc.smooth_intersection{a, b, radius = 0.5}
  nodes.warp = oc.warp(a, {wavelength = 1.1, amplitude = 0.2, seed = 5})
  nodes.transform = oc.transform(nodes.cone, {translate = {0.1, 0, 0},
    rotate = {axis = {1, 1, 0}, angle = 30}, scale = {1.2, 0.9, 1}})
  nodes.perturb = oc.perturb(nodes.segment, {wavelength = 0.8, amplitude = 0.3})
  nodes.scale = -nodes.box
end

-- Points where every node above is smooth (no union/intersection kinks).
local probes = {{0.31, 0.17, -0.23}, {-0.52, 0.41, 0.12}, {0.83, -0.27, 0.36},
  {-0.12, -0.64, 0.47}, {0.05, 0.22, 0.71}}

describe("node:gradient", function()
  for name, n in pairs(nodes) do
    it("matches central differences for " .. name, function()
      for _, p in ipairs(probes) do
        local gx, gy, gz = n:gradient(p[1], p[2], p[3])
        local ng = R.numgrad(n, p, 1e-5)
        local g = {gx, gy, gz}
        for i = 1, 3 do
          R.close(g[i], ng[i], 1e-4 * (1 + math.abs(ng[i])),
            string.format("%s d/d%s at (%g, %g, %g)", name, ("xyz"):sub(i, i),
              p[1], p[2], p[3]))
        end
      end
    end)
  end

  it("accepts a table point", function()
    local n = nodes.point
    local a, b, c = n:gradient{0.3, 0.2, 0.1}
    local x, y, z = n:gradient(0.3, 0.2, 0.1)
    assert.are.same({x, y, z}, {a, b, c})
  end)
end)

describe("node:bounds", function()
  it("of a point is its centre +- radius", function()
    local x0, y0, z0, x1, y1, z1 = nodes.point:bounds()
    local tol = 1.5e-3
    R.close(x0, 0.2 - 1.5, tol); R.close(y0, -0.1 - 1.5, tol); R.close(z0, 0.3 - 1.5, tol)
    R.close(x1, 0.2 + 1.5, tol); R.close(y1, -0.1 + 1.5, tol); R.close(z1, 0.3 + 1.5, tol)
  end)

  it("are infinite for turbulence", function()
    local x0, _, _, x1 = nodes.turbulence:bounds()
    assert.are.equal(-math.huge, x0)
    assert.are.equal(math.huge, x1)
  end)

  for name, n in pairs(nodes) do
    it("hold the support of " .. name, function()
      local b = {n:bounds()}
      assert.are.equal(6, #b)
      for i = 1, 3 do assert.is_true(b[i] <= b[i + 3]) end
      -- nonzero samples lie inside; a grid just outside (when finite) is 0
      for i = -12, 12 do
        for j = -12, 12 do
          local p = {0.25 * i, 0.25 * j, 0.13 * (i + j) / 2}
          if n:eval(p) ~= 0 then
            for k = 1, 3 do
              assert.is_true(p[k] >= b[k] and p[k] <= b[k + 3], name)
            end
          end
        end
      end
      if b[4] < math.huge then
        assert.are.equal(0, n:eval(b[4] + 1e-6, (b[2] + b[5]) / 2, (b[3] + b[6]) / 2))
      end
    end)
  end
end)

describe("node:lipschitz", function()
  it("is |E| Lg / R for a point", function()
    -- a bound: never below the true max slope, and not loose
    local L, exact = nodes.point:lipschitz(), 0.9 * R.Lg / 1.5
    assert.is_true(L >= exact)
    R.close(L, exact, 1e-4 * exact)
  end)

  for name, n in pairs(nodes) do
    it("bounds the gradient of " .. name, function()
      local L = n:lipschitz()
      assert.is_true(L > 0 and L < math.huge)
      for i = -10, 10 do
        local p = {0.17 * i, 0.11 * i - 0.3, 0.05 * i + 0.1}
        local gx, gy, gz = n:gradient(p)
        assert.is_true(math.sqrt(gx * gx + gy * gy + gz * gz) <= L * (1 + 1e-9))
      end
    end)
  end
end)

describe("node:stats", function()
  it("counts one primitive", function()
    local s = nodes.point:stats()
    assert.are.equal(1, s.nodes)
    assert.are.equal(1, s.primitives)
    assert.is_true(math.type(s.bytes) == "integer" and s.bytes > 0)
  end)

  it("counts distinct nodes of a DAG", function()
    local p, q = nodes.point, nodes.sphere
    local s = ((p + q) | p):stats()
    assert.are.equal(2, s.primitives)
    assert.is_true(s.nodes >= 3)
    local t = (p + p):stats()
    assert.are.equal(1, t.primitives)
  end)
end)

describe("outcrop.threshold", function()
  after_each(function() oc.threshold = 0.5 end)

  it("defaults to 0.5", function()
    assert.are.equal(0.5, oc.threshold)
  end)

  it("is read again when it changes (difference is min(fa, 2T - fb))", function()
    local a, b = nodes.point, nodes.segment
    local n = a - b
    local p = {0.3, 0.1, 0.2}
    local fa, fb = a:eval(p), b:eval(p)
    R.close(n:eval(p), math.min(fa, 1 - fb), 1e-12)
    oc.threshold = 0.25
    R.close(n:eval(p), math.min(fa, 0.5 - fb), 1e-12)
    oc.threshold = 0.5
    R.close(n:eval(p), math.min(fa, 1 - fb), 1e-12)
  end)

  it("must be a positive number when a query compiles", function()
    local n = oc.point{center = v0, radius = 1}
    oc.threshold = -1
    R.check_error(function() n:eval(0, 0, 0) end, "queries_spec.lua",
      "node:eval", "outcrop.threshold", "(got -1)")
    oc.threshold = "high"
    R.check_error(function() n:bounds() end, "queries_spec.lua",
      "node:bounds", "outcrop.threshold", "(got string)")
    oc.threshold = 0 / 0
    R.check_error(function() n:lipschitz() end, "queries_spec.lua",
      "node:lipschitz", "outcrop.threshold")
  end)
end)
