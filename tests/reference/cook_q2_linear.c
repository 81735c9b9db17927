/* Independent check: Q2 (9-node) plane-stress FE for Cook's membrane, dense LAPACK solve. */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
static const double V[4][2]={{0,0},{48,44},{48,60},{0,44}};
static void map(double s,double t,double*x){ for(int d=0;d<2;d++) x[d]=(1-s)*(1-t)*V[0][d]+s*(1-t)*V[1][d]+s*t*V[2][d]+(1-s)*t*V[3][d]; }
static void q1d(double r,double*N,double*dN){ N[0]=0.5*r*(r-1); N[1]=1-r*r; N[2]=0.5*r*(r+1); dN[0]=r-0.5; dN[1]=-2*r; dN[2]=r+0.5; }
int main(int argc,char**argv){
  int ne=atoi(argv[1]); int nn=2*ne+1; int ndof=2*nn*nn; double E=1,nu=1.0/3;
  double D[3][3]={{E/(1-nu*nu),E*nu/(1-nu*nu),0},{E*nu/(1-nu*nu),E/(1-nu*nu),0},{0,0,E/(2*(1+nu))}};
  double *K=calloc((size_t)ndof*ndof,8), *f=calloc(ndof,8); double *X=malloc(sizeof(double)*nn*nn*2);
  for(int j=0;j<nn;j++)for(int i=0;i<nn;i++) map((double)i/(nn-1),(double)j/(nn-1),X+2*(j*nn+i));
  double g[3]={-sqrt(0.6),0,sqrt(0.6)}, gw[3]={5.0/9,8.0/9,5.0/9};
  for(int ey=0;ey<ne;ey++)for(int ex=0;ex<ne;ex++){
    int nodes[9]; for(int b=0;b<3;b++)for(int a=0;a<3;a++) nodes[b*3+a]=(2*ey+b)*nn+(2*ex+a);
    for(int qy=0;qy<3;qy++)for(int qx=0;qx<3;qx++){
      double Nx[3],dNx[3],Ny[3],dNy[3]; q1d(g[qx],Nx,dNx); q1d(g[qy],Ny,dNy);
      double dNr[9][2]; for(int b=0;b<3;b++)for(int a=0;a<3;a++){dNr[b*3+a][0]=dNx[a]*Ny[b]; dNr[b*3+a][1]=Nx[a]*dNy[b];}
      double J[2][2]={{0,0},{0,0}}; for(int k=0;k<9;k++)for(int d=0;d<2;d++)for(int r=0;r<2;r++) J[d][r]+=X[2*nodes[k]+d]*dNr[k][r];
      double det=J[0][0]*J[1][1]-J[0][1]*J[1][0]; double Ji[2][2]={{J[1][1]/det,-J[0][1]/det},{-J[1][0]/det,J[0][0]/det}};
      double dN[9][2]; for(int k=0;k<9;k++)for(int d=0;d<2;d++) dN[k][d]=dNr[k][0]*Ji[0][d]+dNr[k][1]*Ji[1][d];
      double w=gw[qx]*gw[qy]*det;
      for(int a=0;a<9;a++)for(int b=0;b<9;b++){
        double Ba[3][2]={{dN[a][0],0},{0,dN[a][1]},{dN[a][1],dN[a][0]}}, Bb[3][2]={{dN[b][0],0},{0,dN[b][1]},{dN[b][1],dN[b][0]}};
        for(int i=0;i<2;i++)for(int j=0;j<2;j++){ double s=0; for(int p=0;p<3;p++)for(int q=0;q<3;q++) s+=Ba[p][i]*D[p][q]*Bb[q][j];
          K[(size_t)(2*nodes[a]+i)*ndof+2*nodes[b]+j]+=w*s; } } } }
  /* traction ty = 1/16 on the right edge (i = nn-1), length element = 16/ne in y */
  for(int ey=0;ey<ne;ey++) for(int q=0;q<3;q++){ double N[3],dNq[3]; q1d(g[q],N,dNq); double L=16.0/ne; for(int b=0;b<3;b++){ int node=(2*ey+b)*nn+(nn-1); f[2*node+1]+=gw[q]*L/2*N[b]/16.0; } }
  for(int j=0;j<nn;j++){ int node=j*nn; for(int c=0;c<2;c++){ int r=2*node+c; for(int k=0;k<ndof;k++){K[(size_t)r*ndof+k]=0;K[(size_t)k*ndof+r]=0;} K[(size_t)r*ndof+r]=1; f[r]=0; } }
  lapack_int *ipiv=malloc(sizeof(lapack_int)*ndof); int info=LAPACKE_dgesv(LAPACK_ROW_MAJOR,ndof,1,K,ndof,ipiv,f,1);
  int tip=(nn-1)*nn+(nn-1); printf("ne=%d info=%d tip (%g,%g) uy=%.5f\n",ne,info,X[2*tip],X[2*tip+1],f[2*tip+1]); return 0; }
