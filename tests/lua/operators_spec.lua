-- operators_spec.lua — operator constructors and node metamethods: each
-- value is checked against the formula applied to the children's values.
local oc = require "outcrop"
local R = require "helpers.ref"

local a = oc.point{center = {0, 0, 0}, radius = 2}
local b = oc.point{center = {1, 0.5, 0}, radius = 1.5, energy = 0.8}
local c = oc.box{min = {-0.5, -0.5, -0.5}, max = {0.5, 1, 0.5}, falloff = 0.7}

local pts = {}
for i = 0, 6 do
  for j = 0, 4 do
    pts[#pts + 1] = {-1.5 + 0.55 * i, -1 + 0.6 * j, 0.3 * (i - j) / 4}
  end
end

local function each(f)
  for _, p in ipairs(pts) do f(p, a:eval(p), b:eval(p), c:eval(p)) end
end

describe("n-ary operators", function()
  it("blend sums", function()
    local n = oc.blend{a, b, c}
    each(function(p, fa, fb, fc) R.close(n:eval(p), fa + fb + fc, 1e-12) end)
  end)
  it("union takes the max", function()
    local n = oc.union{a, b, c}
    each(function(p, fa, fb, fc) R.close(n:eval(p), math.max(fa, fb, fc), 1e-12) end)
  end)
  it("intersection takes the min", function()
    local n = oc.intersection{a, b, c}
    each(function(p, fa, fb, fc) R.close(n:eval(p), math.min(fa, fb, fc), 1e-12) end)
  end)
  it("accept a single child", function()
    for _, f in ipairs{oc.blend, oc.union, oc.intersection} do
      local n = f{b}
      each(function(p, _, fb) R.close(n:eval(p), fb, 1e-12) end)
    end
  end)
  it("accept the same child twice (instancing)", function()
    local n = oc.blend{a, a}
    each(function(p, fa) R.close(n:eval(p), 2 * fa, 1e-12) end)
  end)
end)

describe("difference", function()
  it("is min(fa, 2T - fb)", function()
    local n = oc.difference(a, b)
    each(function(p, fa, fb) R.close(n:eval(p), math.min(fa, 2 * R.T - fb), 1e-12) end)
  end)
end)

describe("smooth operators", function()
  it("smooth_union follows the cubic smooth max with a fading radius", function()
    local n = oc.smooth_union{a, b, radius = 0.4}
    each(function(p, fa, fb)
      R.close(n:eval(p), R.smooth_union(fa, fb, 0.4), 1e-9)
    end)
  end)
  it("smooth_intersection follows the cubic smooth min", function()
    local n = oc.smooth_intersection{a, b, radius = 0.3}
    each(function(p, fa, fb)
      R.close(n:eval(p), R.smooth_intersection(fa, fb, 0.3), 1e-9)
    end)
  end)
  it("keeps compact support", function()
    local far = oc.point{center = {100, 0, 0}, radius = 1}
    local n = oc.smooth_union{a, far, radius = 1}
    R.close(n:eval(50, 0, 0), 0, 0)
  end)
end)

describe("metamethods", function()
  it("a + b blends", function()
    local n = a + b
    assert.are.equal("blend", n:kind())
    each(function(p, fa, fb) R.close(n:eval(p), fa + fb, 1e-12) end)
  end)
  it("a | b is the union", function()
    local n = a | b
    assert.are.equal("union", n:kind())
    each(function(p, fa, fb) R.close(n:eval(p), math.max(fa, fb), 1e-12) end)
  end)
  it("a & b is the intersection", function()
    local n = a & b
    assert.are.equal("intersection", n:kind())
    each(function(p, fa, fb) R.close(n:eval(p), math.min(fa, fb), 1e-12) end)
  end)
  it("a - b is the difference", function()
    local n = a - b
    assert.are.equal("difference", n:kind())
    each(function(p, fa, fb) R.close(n:eval(p), math.min(fa, 2 * R.T - fb), 1e-12) end)
  end)
  it("-a negates the energy", function()
    local n = -a
    assert.are.equal("scale", n:kind())
    each(function(p, fa) R.close(n:eval(p), -fa, 1e-12) end)
  end)
  it("combine: (a + b) | c - -a", function()
    local n = (a + b) | (c - (-a))
    each(function(p, fa, fb, fc)
      R.close(n:eval(p), math.max(fa + fb, math.min(fc, 2 * R.T + fa)), 1e-12)
    end)
  end)
  it("a number operand is an error naming the operator", function()
    for _, f in ipairs{
      function() return a + 1 end, function() return 1 + a end,
      function() return a | 2 end, function() return 3 & a end,
      function() return a - 0.5 end, function() return "x" + a end,
    } do
      local ok, msg = pcall(f)
      assert.is_false(ok)
      assert.matches("operators_spec%.lua:%d+: outcrop: cannot apply '.' %(%a+%) to ", msg)
      assert.matches("must be outcrop nodes", msg)
    end
  end)
end)

describe("warp", function()
  it("is the child when the amplitude is 0", function()
    local n = oc.warp(a, {wavelength = 1, amplitude = 0, seed = 2})
    each(function(p, fa) R.close(n:eval(p), fa, 1e-12) end)
  end)
  it("is the child where the control field is 0", function()
    local ctl = oc.point{center = {50, 0, 0}, radius = 1}
    local n = oc.warp(a, {wavelength = 1, amplitude = 0.5, control = ctl})
    each(function(p, fa) R.close(n:eval(p), fa, 1e-12) end)
  end)
  it("displaces by at most sqrt(3)*A*tmax/2", function()
    local A, o = 0.3, 3
    local n = oc.warp(a, {wavelength = 0.7, amplitude = A, octaves = o, seed = 11})
    local bound = math.sqrt(3) * A * R.tmax(o) / 2 + 1e-9
    local moved = false
    for i = 0, 40 do
      local p = {-1.8 + 0.09 * i, 0.1, 0.2}
      local v = n:eval(p)
      if v > 0 and v < 1 then
        -- distance at which the child has value v
        local d = 2 * math.sqrt(1 - v ^ (1 / 3))
        assert.is_true(math.abs(d - R.len(p)) <= bound)
        if math.abs(v - a:eval(p)) > 1e-6 then moved = true end
      end
    end
    assert.is_true(moved, "warp should move the field")
  end)
end)

describe("perturb", function()
  it("is the primitive when the amplitude is 0", function()
    local n = oc.perturb(a, {wavelength = 1, amplitude = 0})
    each(function(p, fa) R.close(n:eval(p), fa, 1e-12) end)
  end)
  it("stays between E*g(d/R) and E*g(d/(R + A*tmax))", function()
    local A, o = 0.5, 3
    local n = oc.perturb(a, {wavelength = 0.5, amplitude = A, octaves = o, seed = 4})
    local moved = false
    for i = 0, 30 do
      local p = {0.08 * i, 0.03 * i, -0.02 * i}
      local d, v = R.len(p), n:eval(p)
      local lo, hi = R.g(d / 2), R.g(d / (2 + A * R.tmax(o)))
      assert.is_true(v >= lo - 1e-12 and v <= hi + 1e-12)
      if v > lo + 1e-6 then moved = true end
    end
    assert.is_true(moved)
  end)
end)

describe("transform", function()
  local p0 = oc.point{center = {1, 0, 0}, radius = 1}
  it("translates", function()
    local n = oc.transform(p0, {translate = {2, 3, 4}})
    R.close(n:eval(3, 3, 4), 1, 1e-12)
    R.close(n:eval(3.5, 3, 4), p0:eval(1.5, 0, 0), 1e-12)
  end)
  it("rotates about an axis, angle in degrees", function()
    local n = oc.transform(p0, {rotate = {axis = {0, 0, 1}, angle = 90}})
    R.close(n:eval(0, 1, 0), 1, 1e-12)
    -- M^-1 turns (0.5, 0.8, 0) by -90 degrees to (0.8, -0.5, 0)
    R.close(n:eval(0.5, 0.8, 0), p0:eval(0.8, -0.5, 0), 1e-12)
    assert.is_true(n:eval(0.5, 0.8, 0) > 0)
  end)
  it("rotates by Euler angles X then Y then Z", function()
    local n = oc.transform(p0, {rotate = {90, 0, 90}})
    -- (1,0,0): X leaves it, Z turns it to (0,1,0)
    R.close(n:eval(0, 1, 0), 1, 1e-12)
    local q = oc.point{center = {0, 1, 0}, radius = 1}
    local m = oc.transform(q, {rotate = {90, 0, 90}})
    -- (0,1,0): X turns it to (0,0,1), Z leaves it
    R.close(m:eval(0, 0, 1), 1, 1e-12)
  end)
  it("scales uniformly and per axis", function()
    local n = oc.transform(p0, {scale = 2})
    R.close(n:eval(2, 0, 0), 1, 1e-12)
    R.close(n:eval(3, 0, 0), (1 - 0.25) ^ 3, 1e-12)
    local m = oc.transform(p0, {scale = {2, 1, 0.5}})
    R.close(m:eval(2, 0, 0.25), p0:eval(1, 0, 0.5), 1e-12)
  end)
  it("applies scale, then rotate, then translate", function()
    local axis, ang = {1, 2, 3}, 37
    local n = oc.transform(c, {translate = {1, -2, 0.5},
      rotate = {axis = axis, angle = ang}, scale = {1.5, 0.5, 2}})
    each(function(p)
      -- M^-1 p = S^-1 R^-1 (p - t)
      local q = R.rotate(R.sub(p, {1, -2, 0.5}), axis, -ang)
      q = {q[1] / 1.5, q[2] / 0.5, q[3] / 2}
      R.close(n:eval(p), c:eval(q), 1e-9)
    end)
  end)
  it("is the identity with no field", function()
    local n = oc.transform(b, {})
    each(function(p, _, fb) R.close(n:eval(p), fb, 1e-12) end)
  end)
end)

describe("tostring", function()
  it("names the kind", function()
    assert.are.equal("outcrop.node: point", tostring(a))
    assert.are.equal("outcrop.node: blend", tostring(a + b))
  end)
end)
