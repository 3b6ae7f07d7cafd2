#!/usr/bin/env python3
"""Hunt scenes: balls in a row on a slope or floor (README, The hunt for wrong greens, balls in a row).

Writes physval scenes with an [expect] block from the rigid Coulomb closed form (blocks pooled from
the front ball; see core/tests/resting_contact_test.cpp) into DIR:
  row*.toml  3 and 4 balls released at rest on slopes of 10 to 72 degrees;
  fl*.toml   2 to 4 balls sliding at v0 on a floor or a 15 degree slope until they stop.
Cases within 1e-6 g of a threshold are left out. Run them with
  for f in DIR/*.toml; do build/physval run "$f" || echo "FAIL $f"; done
Usage: scripts/hunt_balls_in_a_row.py DIR
"""
import math
import os
import sys

out = sys.argv[1] if len(sys.argv) > 1 else "hunt-balls-in-a-row"
os.makedirs(out, exist_ok=True)
os.chdir(out)

g=9.8
mus=[(0.5,0.2,0.2),(1.0,0.1,0.5),(2.0,0.05,0.05),(0.2,0.2,0.5),(0.6,0.3,0.0),(0.5,0.2,0.2,0.2),(0.1,1.0,0.1,1.0),(1.0,0.1,0.1,0.6),(2.0,0.05,0.5,0.05),(0.3,0.3,0.3),(0.2,0.2,0.2,0.2)]
masses=[(1,1,1,1),(0.01,1,100,1),(100,1,0.01,10),(1,100,1,0.01)]
slopes=[10,20,35,50,72]
n=0
for deg in slopes:
  th=math.radians(deg); t=(math.cos(th),math.sin(th)); nr=(-math.sin(th),math.cos(th))
  for mu in mus:
    N=len(mu)
    for mass in masses:
      for rev in (False,True):
        def alone(b,e):
          M=sum(mass[k] for k in range(b,e)); F=sum(mass[k]*g*(math.sin(th)-mu[k]*math.cos(th)) for k in range(b,e)); return F/M
        blocks=[]; near=False
        for k in range(N):
          blocks.append([k,k+1])
          while len(blocks)>1:
            fb,fe=blocks[-2]; bb,be=blocks[-1]
            af=max(0,alone(fb,fe)); ab=max(0,alone(bb,be))
            gap=abs(ab-af)
            if 1e-12*g<gap<1e-6*g and (ab>0 or af>0): near=True
            if not ab>af: break
            blocks.pop(); blocks[-1][1]=be
        a=[0]*N
        for b,e in blocks:
          u=alone(b,e)
          if abs(u)<1e-6*g: near=True
          for k in range(b,e): a[k]=max(0,u)
        if near: continue
        n+=1
        L=[]
        L.append(f'name = "row{n}"\ndescription = "{N} balls on a {deg} degree slope, mu {mu}, masses {mass[:N]}, closed form a {a}"\nengines = ["core"]\nduration = 1.0\ndt = "1/60"\n[world]\ngravity = [0.0, -9.8]\n')
        order=list(range(N))[::-1] if rev else list(range(N))
        for k in order:
          p=((20+k)*t[0]+0.5*nr[0],(20+k)*t[1]+0.5*nr[1])
          L.append(f'[[bodies]]\nname = "b{k}"\nradius = 0.5\nmass = {mass[k]}\nposition = [{p[0]!r}, {p[1]!r}]\nrestitution = 0.0\n')
        L.append(f'[[walls]]\nname = "slope"\nfrom = [0.0, 0.0]\nto = [{40*t[0]!r}, {40*t[1]!r}]\nrestitution = 0.0\n')
        for k in range(N):
          L.append(f'[[materials]]\na = "b{k}"\nb = "slope"\nfriction = {mu[k]}\n')
          for l in range(k+1,N):
            L.append(f'[[materials]]\na = "b{k}"\nb = "b{l}"\nfriction = 0.0\n')
        ex=[]
        for k in range(N):
          p=((20+k)*t[0]+0.5*nr[0]-0.5*a[k]*t[0],(20+k)*t[1]+0.5*nr[1]-0.5*a[k]*t[1])
          v=(-a[k]*t[0],-a[k]*t[1])
          ex.append(f'{{ body = "b{k}", position = [{p[0]!r}, {p[1]!r}], velocity = [{v[0]!r}, {v[1]!r}], tolerance = 1e-6 }}')
        L.append('[expect]\nfinal = [ '+',\n  '.join(ex)+' ]\n')
        open(f'row{n:03d}.toml','w').write(''.join(L))
print("rows", n)

g=9.8
mus=[(0.5,0.2,0.2),(1.0,0.1,0.5),(0.2,0.2,0.5),(0.6,0.3,0.05),(0.5,0.2,0.2,0.2),(0.1,1.0,0.1,1.0),(1.0,0.1,0.1,0.6),(0.3,0.3,0.3),(0.4,0.2),(0.2,0.4)]
masses=[(1,1,1,1),(0.01,1,100,1),(100,1,0.01,10),(1,100,1,0.01)]
n=0
for deg in (0.0, 15.0):
 th=math.radians(deg); t=(math.cos(th),math.sin(th)); nr=(-math.sin(th),math.cos(th))
 for v0 in (1.0, 3.0, 6.0):
  for mu in mus:
    N=len(mu)
    for mass in masses:
      for rev in (False,True):
        def alone(b,e):   # acceleration down the slope (the direction of motion) while moving
          M=sum(mass[k] for k in range(b,e)); return sum(mass[k]*g*(math.sin(th)-mu[k]*math.cos(th)) for k in range(b,e))/M
        blocks=[]; near=False
        for k in range(N):
          blocks.append([k,k+1])
          while len(blocks)>1:
            fb,fe=blocks[-2]; bb,be=blocks[-1]
            af=alone(fb,fe); ab=alone(bb,be)
            if 1e-12*g<abs(ab-af)<1e-6*g: near=True
            if not ab>af: break
            blocks.pop(); blocks[-1][1]=be
        def state(k,T):
          for b,e in blocks:
            if b<=k<e: a=alone(b,e)
          if a<0:
            ts=v0/(-a)
            if abs(ts-1.0)<1e-3: return None
            if T>ts:
              # stopped: stays iff static friction holds each block alone (tan <= mu for all... block)
              M=sum(mass[j] for j in range(b,e)); F=sum(mass[j]*math.sin(th) for j in range(b,e)); H=sum(mass[j]*mu[j]*math.cos(th) for j in range(b,e))
              return (v0*ts+0.5*a*ts*ts, 0.0, F<=H*(1-1e-9) )
          return (v0*T+0.5*a*T*T, v0+a*T, True)
        res=[state(k,1.0) for k in range(N)]
        if near or any(r is None or not r[2] for r in res): continue
        # after stops, a stopped block behind a moving one: no contact; a stopped block in front of a moving one cannot happen (pooled)
        n+=1
        L=[f'name = "fl{n}"\ndescription = "{N} balls, {deg} deg, v0 {v0}, mu {mu}, masses {mass[:N]}"\nengines = ["core"]\nduration = 1.0\ndt = "1/60"\n[world]\ngravity = [0.0, -9.8]\n']
        order=list(range(N))[::-1] if rev else list(range(N))
        for k in order:
          p=((20+k)*t[0]+0.5*nr[0],(20+k)*t[1]+0.5*nr[1])
          L.append(f'[[bodies]]\nname = "b{k}"\nradius = 0.5\nmass = {mass[k]}\nposition = [{p[0]!r}, {p[1]!r}]\nvelocity = [{-v0*t[0]!r}, {-v0*t[1]!r}]\nrestitution = 0.0\n')
        L.append(f'[[walls]]\nname = "floor"\nfrom = [0.0, 0.0]\nto = [{40*t[0]!r}, {40*t[1]!r}]\nrestitution = 0.0\n')
        for k in range(N):
          L.append(f'[[materials]]\na = "b{k}"\nb = "floor"\nfriction = {mu[k]}\n')
          for l in range(k+1,N):
            L.append(f'[[materials]]\na = "b{k}"\nb = "b{l}"\nfriction = 0.0\n')
        ex=[]
        for k in range(N):
          s,v,_=res[k]
          p=((20+k)*t[0]+0.5*nr[0]-s*t[0],(20+k)*t[1]+0.5*nr[1]-s*t[1])
          ex.append(f'{{ body = "b{k}", position = [{p[0]!r}, {p[1]!r}], velocity = [{-v*t[0]!r}, {-v*t[1]!r}], tolerance = 1e-6 }}')
        L.append('[expect]\nfinal = [ '+',\n  '.join(ex)+' ]\n')
        open(f'fl{n:03d}.toml','w').write(''.join(L))
print("stops", n)
