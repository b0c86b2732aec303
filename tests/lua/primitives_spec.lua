-- primitives_spec.lua — every primitive constructor against the formulas
-- of docs/fields.md, evaluated independently in helpers/ref.lua.
local oc = require "outcrop"
local R = require "helpers.ref"

-- Deterministic sample points around a centre.
local function samples(center, spread, n)
  local pts, s = {}, 12345
  local function rnd()
    s = (s * 1103515245 + 12345) % 2147483648
    return s / 2147483648
  end
  for i = 1, n do
    pts[i] = {center[1] + (2 * rnd() - 1) * spread,
      center[2] + (2 * rnd() - 1) * spread,
      center[3] + (2 * rnd() - 1) * spread}
  end
  return pts
end

local function check_all(node, pts, ref, tol)
  for i, p in ipairs(pts) do
    R.close(node:eval(p[1], p[2], p[3]), ref(p), tol or 1e-9,
      string.format("sample %d at (%g, %g, %g)", i, p[1], p[2], p[3]))
  end
end

describe("outcrop.point", function()
  it("is E*g(|p - c| / R)", function()
    local c, r, e = {0.5, -1, 2}, 3, 0.8
    local n = oc.point{center = c, radius = r, energy = e}
    R.close(n:eval(0.5, -1, 2), 0.8)
    R.close(n:eval(0.5 + 1.5, -1, 2), 0.8 * (1 - 0.25) ^ 3)
    R.close(n:eval(0.5, -1, 2 + 3.01), 0)
    check_all(n, samples(c, 4, 60), function(p)
      return e * R.g(R.dist_point(p, c) / r)
    end)
  end)

  it("defaults energy to 1 and accepts {x=, y=, z=} vectors", function()
    local n = oc.point{center = {x = 1, y = 2, z = 3}, radius = 2}
    R.close(n:eval(1, 2, 3), 1)
    R.close(n:eval(2, 2, 3), (1 - 0.25) ^ 3)
  end)

  it("accepts a table point in eval", function()
    local n = oc.point{center = {0, 0, 0}, radius = 1}
    R.close(n:eval{0.5, 0, 0}, n:eval(0.5, 0, 0), 0)
    R.close(n:eval{x = 0, y = 0.5, z = 0}, n:eval(0, 0.5, 0), 0)
  end)

  it("carves with a negative energy", function()
    local n = oc.point{center = {0, 0, 0}, radius = 1, energy = -2}
    R.close(n:eval(0, 0, 0), -2)
  end)
end)

describe("outcrop.sphere", function()
  it("is E inside the ball and E*g((|p-c| - r)/R) outside", function()
    local c, r, fo, e = {1, 0, -1}, 2, 1.5, 1.2
    local n = oc.sphere{center = c, radius = r, falloff = fo, energy = e}
    R.close(n:eval(1, 0, -1), 1.2)
    R.close(n:eval(2.9, 0, -1), 1.2)
    check_all(n, samples(c, 4, 60), function(p)
      return e * R.g(math.max(0, R.dist_point(p, c) - r) / fo)
    end)
  end)

  it("defaults the falloff to the radius", function()
    local n = oc.sphere{center = {0, 0, 0}, radius = 2}
    check_all(n, samples({0, 0, 0}, 4.5, 40), function(p)
      return R.g(math.max(0, R.len(p) - 2) / 2)
    end)
  end)
end)

describe("outcrop.box", function()
  it("is E*g(d/R) with d the distance to the solid box", function()
    local lo, hi, fo, e = {-1, -2, 0}, {1, 2, 0.5}, 0.75, 0.9
    local n = oc.box{min = lo, max = hi, falloff = fo, energy = e}
    R.close(n:eval(0, 0, 0.25), 0.9)
    check_all(n, samples({0, 0, 0.25}, 3, 80), function(p)
      return e * R.g(R.dist_box(p, lo, hi) / fo)
    end)
  end)

  it("defaults the falloff to 1", function()
    local n = oc.box{min = {0, 0, 0}, max = {1, 1, 1}}
    R.close(n:eval(1.5, 0.5, 0.5), (1 - 0.25) ^ 3)
    R.close(n:eval(2.01, 0.5, 0.5), 0)
  end)
end)

describe("outcrop.segment", function()
  it("is E*g(d/R), d the distance to [a, b]", function()
    local a, b, r = {0, 0, 0}, {4, 1, -1}, 1.3
    local n = oc.segment{a = a, b = b, radius = r, energy = 0.7}
    check_all(n, samples({2, 0.5, -0.5}, 3.5, 80), function(p)
      return 0.7 * R.g(R.dist_segment(p, a, b) / r)
    end)
  end)

  it("is a point when a = b", function()
    local s = oc.segment{a = {1, 1, 1}, b = {1, 1, 1}, radius = 2}
    local p = oc.point{center = {1, 1, 1}, radius = 2}
    for _, q in ipairs(samples({1, 1, 1}, 2.5, 20)) do
      R.close(s:eval(q), p:eval(q), 1e-12)
    end
  end)
end)

describe("outcrop.curve", function()
  it("follows the polyline through its points", function()
    local pts = {{0, 0, 0}, {2, 0, 0}, {2, 2, 1}, {0, 3, 1}}
    local n = oc.curve{points = pts, radius = 0.8, energy = 1.1}
    check_all(n, samples({1, 1.5, 0.5}, 2.5, 100), function(p)
      return 1.1 * R.g(R.dist_polyline(p, pts) / 0.8)
    end)
  end)

  it("flattens a composite cubic Bezier within 1e-4 R", function()
    local ctrl = {{0, 0, 0}, {1, 2, 0}, {3, 2, 0}, {4, 0, 0},
      {5, -2, 0}, {7, -2, 1}, {8, 0, 1}}
    local r = 1
    local n = oc.curve{points = ctrl, radius = r, bezier = true}
    local dense = R.bezier_polyline(ctrl, 3000)
    -- |dg/dd| <= Lg / R, so a distance error of 1e-4 R moves f by < 2e-4.
    check_all(n, samples({4, 0, 0.5}, 4, 60), function(p)
      return R.g(R.dist_polyline(p, dense) / r)
    end, 3e-4)
  end)

  it("passes through the Bezier end points, not the inner controls", function()
    local ctrl = {{0, 0, 0}, {0, 10, 0}, {10, 10, 0}, {10, 0, 0}}
    local n = oc.curve{points = ctrl, radius = 0.5, bezier = true}
    R.close(n:eval(0, 0, 0), 1, 1e-9)
    R.close(n:eval(10, 0, 0), 1, 1e-9)
    R.close(n:eval(0, 10, 0), 0, 0) -- a control point off the curve
    R.close(n:eval(5, 7.5, 0), 1, 1e-6) -- B(1/2) = (5, 7.5, 0)
  end)
end)

describe("outcrop.cone", function()
  it("is E*g(d/R) with d the distance to the solid cone", function()
    local base, apex, r, fo = {0, 0, 0}, {0, 0, 3}, 1.5, 0.8
    local n = oc.cone{base = base, apex = apex, radius = r, falloff = fo,
      energy = 1.4}
    R.close(n:eval(0, 0, 1), 1.4)
    check_all(n, samples({0, 0, 1.5}, 3, 100), function(p)
      return 1.4 * R.g(R.dist_cone(p, base, apex, r) / fo)
    end)
  end)

  it("works on a tilted axis and defaults the falloff to the radius", function()
    local base, apex, r = {1, 2, 3}, {3, 0, 4}, 1
    local n = oc.cone{base = base, apex = apex, radius = r}
    check_all(n, samples({2, 1, 3.5}, 2.5, 100), function(p)
      return R.g(R.dist_cone(p, base, apex, r) / r)
    end)
  end)
end)

describe("outcrop.plane", function()
  it("is E on the side opposite the normal, falling over R", function()
    local o, nrm, fo = {0, 0, 1}, {0, 0, 2}, 2
    local n = oc.plane{origin = o, normal = nrm, falloff = fo, energy = 0.6}
    R.close(n:eval(100, -50, 0), 0.6)
    R.close(n:eval(0, 0, 2), 0.6 * (1 - 0.25) ^ 3)
    R.close(n:eval(0, 0, 3.01), 0)
  end)

  it("normalises a tilted normal and defaults the falloff to 1", function()
    local o, nrm = {1, 1, 1}, {1, 1, 0}
    local n = oc.plane{origin = o, normal = nrm}
    local u = R.mul(nrm, 1 / R.len(nrm))
    check_all(n, samples(o, 2, 60), function(p)
      return R.g(math.max(0, R.dot(R.sub(p, o), u)))
    end)
  end)
end)

describe("outcrop.turbulence", function()
  it("stays in [offset, offset + A*tmax]", function()
    local n = oc.turbulence{wavelength = 3, amplitude = 2, octaves = 5,
      offset = -1, seed = 9}
    local lo, hi = math.huge, -math.huge
    for _, p in ipairs(samples({0, 0, 0}, 20, 400)) do
      local v = n:eval(p)
      lo, hi = math.min(lo, v), math.max(hi, v)
    end
    assert.is_true(lo >= -1 and hi <= -1 + 2 * R.tmax(5))
    assert.is_true(hi - lo > 0.1, "turbulence should vary")
  end)

  it("is deterministic and depends on the seed", function()
    local a = oc.turbulence{wavelength = 2, seed = 3}
    local b = oc.turbulence{wavelength = 2, seed = 3}
    local c = oc.turbulence{wavelength = 2, seed = 4}
    local differ = false
    for _, p in ipairs(samples({5, 5, 5}, 10, 50)) do
      assert.are.equal(a:eval(p), b:eval(p))
      if a:eval(p) ~= c:eval(p) then differ = true end
    end
    assert.is_true(differ)
  end)

  it("defaults: amplitude 1, octaves 4, offset 0, seed = scene seed", function()
    local reg = debug.getregistry()
    local saved = reg["outcrop.seed"]
    reg["outcrop.seed"] = 77
    local d = oc.turbulence{wavelength = 2}
    reg["outcrop.seed"] = saved
    local e = oc.turbulence{wavelength = 2, amplitude = 1, octaves = 4,
      offset = 0, seed = 77}
    for _, p in ipairs(samples({0, 0, 0}, 10, 50)) do
      assert.are.equal(e:eval(p), d:eval(p))
    end
  end)

  it("scales by the wavelength", function()
    local a = oc.turbulence{wavelength = 1, seed = 5}
    local b = oc.turbulence{wavelength = 4, seed = 5}
    for _, p in ipairs(samples({1, 2, 3}, 5, 30)) do
      R.close(b:eval(4 * p[1], 4 * p[2], 4 * p[3]), a:eval(p), 1e-12)
    end
  end)
end)

describe("node:kind", function()
  it("names every primitive", function()
    local v = {0, 0, 0}
    assert.are.equal("point", oc.point{center = v, radius = 1}:kind())
    assert.are.equal("sphere", oc.sphere{center = v, radius = 1}:kind())
    assert.are.equal("box", oc.box{min = v, max = {1, 1, 1}}:kind())
    assert.are.equal("segment", oc.segment{a = v, b = {1, 0, 0}, radius = 1}:kind())
    assert.are.equal("curve", oc.curve{points = {v, {1, 0, 0}}, radius = 1}:kind())
    assert.are.equal("cone", oc.cone{base = v, apex = {0, 0, 1}, radius = 1}:kind())
    assert.are.equal("plane", oc.plane{origin = v, normal = {0, 0, 1}}:kind())
    assert.are.equal("turbulence", oc.turbulence{wavelength = 1}:kind())
  end)
end)
